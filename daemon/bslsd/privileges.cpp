#include "privileges.h"

#include <grp.h>
#include <pwd.h>
#include <sys/capability.h>
#include <sys/prctl.h>
#include <unistd.h>

#include <cerrno>
#include <charconv>
#include <cstring>
#include <fstream>
#include <optional>
#include <sstream>
#include <string_view>

namespace bsls::bslsd {

Result<CapabilitySets> ReadCapabilitySets(const std::string& status_path) {
  std::ifstream in(status_path);
  if (!in) return Status(ErrorCode::kUnavailable, "cannot read " + status_path);
  CapabilitySets sets;
  int found = 0;
  for (std::string line; std::getline(in, line);) {
    auto field = [&](const char* name, unsigned long long& out) {
      const std::size_t n = std::strlen(name);
      if (line.compare(0, n, name) != 0) return;
      out = std::stoull(line.substr(n), nullptr, 16);
      ++found;
    };
    field("CapInh:", sets.inheritable);
    field("CapPrm:", sets.permitted);
    field("CapEff:", sets.effective);
    field("CapBnd:", sets.bounding);
    field("CapAmb:", sets.ambient);
  }
  if (found < 5) return Status(ErrorCode::kUnavailable, status_path + " lacks the Cap* lines");
  return sets;
}

int ThreadCount() {
  std::ifstream in("/proc/self/status");
  for (std::string line; std::getline(in, line);)
    if (line.rfind("Threads:", 0) == 0) return std::stoi(line.substr(8));
  return -1;
}

namespace {

// The unsigned number that is the whole of `text`.
std::optional<unsigned> WholeNumber(std::string_view text) {
  unsigned value = 0;
  const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (text.empty() || error != std::errc() || end != text.data() + text.size()) return std::nullopt;
  return value;
}

std::string Errno(const std::string& what) { return what + ": " + std::strerror(errno); }

// The ids as getresuid/getresgid see them: all three equal to `uid`/`gid`.
bool IdsAre(uid_t uid, gid_t gid) {
  uid_t ruid, euid, suid;
  gid_t rgid, egid, sgid;
  return ::getresuid(&ruid, &euid, &suid) == 0 && ::getresgid(&rgid, &egid, &sgid) == 0 &&
         ruid == uid && euid == uid && suid == uid && rgid == gid && egid == gid && sgid == gid;
}

}  // namespace

Result<Identity> ResolveIdentity(const std::string& user) {
  Identity identity;
  identity.name = user;
  if (const std::size_t colon = user.find(':'); colon != std::string::npos) {
    const std::optional<unsigned> uid = WholeNumber(std::string_view(user).substr(0, colon));
    const std::optional<unsigned> gid = WholeNumber(std::string_view(user).substr(colon + 1));
    if (!uid || !gid)
      return Status(ErrorCode::kInvalidArgument,
                    "user: '" + user + "' is neither a user name nor UID:GID numbers");
    identity.uid = *uid;
    identity.gid = *gid;
    return identity;
  }
  std::vector<char> buffer(16384);
  passwd entry{};
  passwd* found = nullptr;
  if (::getpwnam_r(user.c_str(), &entry, buffer.data(), buffer.size(), &found) != 0 ||
      found == nullptr)
    return Status(ErrorCode::kInvalidArgument,
                  "user: '" + user +
                      "' does not exist on this machine; bslsd started as root switches to it "
                      "and refuses to serve as root (create it, e.g. with systemd-sysusers and "
                      "bsls.sysusers.conf, or name another account in `user:`)");
  identity.uid = found->pw_uid;
  identity.gid = found->pw_gid;
  int count = 32;
  for (;;) {
    identity.groups.resize(count);
    const int previous = count;
    if (::getgrouplist(user.c_str(), identity.gid, identity.groups.data(), &count) >= 0) break;
    if (count <= previous) count = previous * 2;  // older glibc: no size given back
  }
  identity.groups.resize(count);
  return identity;
}

Status DropAllCapabilities(const std::optional<Identity>& identity) {
  if (const int threads = ThreadCount(); threads != 1)
    return Status(ErrorCode::kInternal,
                  "capabilities must be dropped while bslsd has one thread; it has " +
                      std::to_string(threads));
  // The bounding set first: it needs CAP_SETPCAP, which the next step removes.
  if (CAP_IS_SUPPORTED(CAP_SETPCAP)) {
    cap_t current = cap_get_proc();
    cap_flag_value_t setpcap = CAP_CLEAR;
    if (current != nullptr) {
      cap_get_flag(current, CAP_SETPCAP, CAP_EFFECTIVE, &setpcap);
      cap_free(current);
    }
    if (setpcap == CAP_SET) {
      for (cap_value_t cap = 0; cap <= CAP_LAST_CAP; ++cap) ::prctl(PR_CAPBSET_DROP, cap, 0, 0, 0);
    }
  }
  // The identity next, while CAP_SETGID and CAP_SETUID are still held:
  // groups, then the gid, then the uid (after which they are gone).
  if (identity) {
    if (::setgroups(identity->groups.size(), identity->groups.data()) != 0)
      return Status(ErrorCode::kPermissionDenied,
                    Errno("setting the supplementary groups of user '" + identity->name + "'"));
    if (::setresgid(identity->gid, identity->gid, identity->gid) != 0)
      return Status(ErrorCode::kPermissionDenied,
                    Errno("switching to gid " + std::to_string(identity->gid) + " of user '" +
                          identity->name + "'"));
    if (::setresuid(identity->uid, identity->uid, identity->uid) != 0)
      return Status(ErrorCode::kPermissionDenied,
                    Errno("switching to uid " + std::to_string(identity->uid) + " of user '" +
                          identity->name + "'"));
    if (!IdsAre(identity->uid, identity->gid))
      return Status(ErrorCode::kPermissionDenied, "bslsd did not become user '" + identity->name +
                                                      "' (uid " + std::to_string(identity->uid) +
                                                      ", gid " + std::to_string(identity->gid) +
                                                      ")");
  }
  if (::prctl(PR_CAP_AMBIENT, PR_CAP_AMBIENT_CLEAR_ALL, 0, 0, 0) != 0 && errno != EINVAL)
    return Status(ErrorCode::kPermissionDenied,
                  std::string("clearing the ambient capabilities failed: ") + std::strerror(errno));
  cap_t none = cap_init();  // every flag clear
  if (none == nullptr) return Status(ErrorCode::kInternal, "cap_init failed");
  const int rc = cap_set_proc(none);
  const int saved = errno;
  cap_free(none);
  if (rc != 0)
    return Status(ErrorCode::kPermissionDenied,
                  std::string("dropping every capability failed: ") + std::strerror(saved));
  if (::prctl(PR_SET_NO_NEW_PRIVS, 1, 0, 0, 0) != 0)
    return Status(ErrorCode::kPermissionDenied,
                  std::string("setting no_new_privs failed: ") + std::strerror(errno));
  Result<CapabilitySets> sets = ReadCapabilitySets("/proc/self/status");
  if (!sets.ok()) return sets.status();
  if (!sets->None()) {
    std::ostringstream left;
    left << std::hex << "CapEff " << sets->effective << ", CapPrm " << sets->permitted
         << ", CapAmb " << sets->ambient;
    return Status(ErrorCode::kPermissionDenied,
                  "capabilities are still held after dropping them (" + left.str() +
                      "); bslsd refuses to serve with them");
  }
  return {};
}

}  // namespace bsls::bslsd
