#include "bsls/service/roles.h"

#include <grp.h>
#include <pwd.h>

#include <algorithm>
#include <array>
#include <utility>
#include <vector>

namespace bsls::service {

std::string_view ToString(Role role) {
  switch (role) {
    case Role::kNone:
      return "none";
    case Role::kViewer:
      return "viewer";
    case Role::kOperator:
      return "operator";
    case Role::kAdmin:
      return "admin";
  }
  return "none";
}

std::optional<Role> ParseRole(std::string_view text) {
  for (Role role : {Role::kNone, Role::kViewer, Role::kOperator, Role::kAdmin})
    if (ToString(role) == text) return role;
  return std::nullopt;
}

std::string Caller::Describe() const {
  std::string out = name.empty() ? std::string("?") : name;
  out += " (";
  if (uid >= 0) out += "uid " + std::to_string(uid) + ", ";
  out += transport + ", " + std::string(ToString(role)) + ")";
  return out;
}

Role RolePolicy::RoleOfUid(uid_t uid) const {
  Role role = others;
  if (auto it = users.find(uid); it != users.end()) role = std::max(role, it->second);
  if (groups.empty()) return role;
  // The user's groups: its primary group and every supplementary one.
  std::vector<char> buffer(16384);
  passwd entry{};
  passwd* found = nullptr;
  if (::getpwuid_r(uid, &entry, buffer.data(), buffer.size(), &found) != 0 || found == nullptr)
    return role;
  int count = 64;
  std::vector<gid_t> gids(static_cast<std::size_t>(count));
  if (::getgrouplist(found->pw_name, found->pw_gid, gids.data(), &count) < 0) {
    gids.resize(static_cast<std::size_t>(count));
    if (::getgrouplist(found->pw_name, found->pw_gid, gids.data(), &count) < 0) return role;
  }
  gids.resize(static_cast<std::size_t>(count));
  for (gid_t gid : gids)
    if (auto it = groups.find(gid); it != groups.end()) role = std::max(role, it->second);
  return role;
}

Role RolePolicy::RoleOfCertificate(std::string_view common_name) const {
  auto it = certificate_names.find(std::string(common_name));
  return it == certificate_names.end() ? Role::kNone : it->second;
}

Role RequiredRole(std::string_view method) {
  static constexpr std::array<std::pair<std::string_view, Role>, 14> kTable{{
      {"GetStatus", Role::kViewer},
      {"StreamPreview", Role::kViewer},
      {"ListCaptures", Role::kViewer},
      {"GetCapture", Role::kViewer},
      {"GetCaptureResult", Role::kViewer},
      {"GetSlideState", Role::kViewer},
      {"WatchEvents", Role::kViewer},
      {"SelectCamera", Role::kOperator},
      {"SetGain", Role::kOperator},
      {"Grab", Role::kOperator},
      {"SetSlide", Role::kOperator},
      {"SetFocus", Role::kOperator},
      {"SetLamp", Role::kOperator},
      {"DeleteCapture", Role::kAdmin},
  }};
  constexpr std::string_view kPrefix = "/bsls.v1.CaptureDaemon/";
  if (method.substr(0, kPrefix.size()) != kPrefix) return Role::kAdmin;
  method.remove_prefix(kPrefix.size());
  for (const auto& [name, role] : kTable)
    if (name == method) return role;
  return Role::kAdmin;
}

}  // namespace bsls::service
