// Least privilege for bslsd: the daemon may start with
// CAP_SYS_RAWIO (for /dev/port or ioperm) and nothing else, or as root; it
// opens the devices that need a privilege and its socket while it is still
// single-threaded, then (started as root) becomes the configured user and
// drops every capability for good. Ids and capabilities are per thread in
// Linux, so the drop must come before any thread exists (gRPC, libusb, the
// capture thread).
#ifndef BSLS_BSLSD_PRIVILEGES_H_
#define BSLS_BSLSD_PRIVILEGES_H_

#include <sys/types.h>

#include <optional>
#include <string>
#include <vector>

#include "bsls/common/status.h"

namespace bsls::bslsd {

// The capability sets of a thread as /proc shows them (hex masks).
struct CapabilitySets {
  unsigned long long effective = 0;
  unsigned long long permitted = 0;
  unsigned long long inheritable = 0;
  unsigned long long ambient = 0;
  unsigned long long bounding = 0;

  // True when the effective, permitted and ambient sets are empty.
  bool None() const { return effective == 0 && permitted == 0 && ambient == 0; }
};

// The sets of `status_path` (/proc/self/status or /proc/PID/task/TID/status).
Result<CapabilitySets> ReadCapabilitySets(const std::string& status_path);

// The account a daemon started as root switches to: its uid, primary gid
// and supplementary groups.
struct Identity {
  std::string name;  // as the configuration gave it (for messages)
  uid_t uid = 0;
  gid_t gid = 0;
  std::vector<gid_t> groups;  // supplementary groups (the user's, from the group database)
};

// The account of the configuration's `user` key: a user name (its primary
// group and every group it is a member of) or "UID:GID" numbers (no
// supplementary groups). kInvalidArgument naming the key and the user when
// there is no such user.
Result<Identity> ResolveIdentity(const std::string& user);

// Drops every privilege for good: the bounding set where CAP_SETPCAP allows;
// then, given an identity (started as root), switches the groups, gid and
// uid (real, effective and saved) to it; then clears the ambient,
// inheritable, permitted and effective sets, sets no_new_privs, and checks
// /proc/self/status and the ids: kPermissionDenied naming what is left when
// anything is. Must be called while the process has a single thread (ids
// and capabilities are per thread in Linux).
Status DropAllCapabilities(const std::optional<Identity>& identity = std::nullopt);

// The number of threads of this process (from /proc/self/status).
int ThreadCount();

}  // namespace bsls::bslsd

#endif  // BSLS_BSLSD_PRIVILEGES_H_
