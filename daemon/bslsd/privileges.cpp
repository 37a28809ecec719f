#include "privileges.h"

#include <sys/capability.h>
#include <sys/prctl.h>

#include <cerrno>
#include <cstring>
#include <fstream>
#include <sstream>

namespace bsls::bslsd {

using framestore::ErrorCode;
using framestore::Result;
using framestore::Status;

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

Status DropAllCapabilities() {
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
