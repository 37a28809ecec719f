// Least privilege for bslsd (issue 4): the daemon may start with
// CAP_SYS_RAWIO (for /dev/port or ioperm) and nothing else; it opens the
// devices that need it while it is still single-threaded, then drops every
// capability for good. Capabilities are per thread in Linux, so the drop
// must come before any thread exists (gRPC, libusb, the capture thread).
#ifndef BSLS_BSLSD_PRIVILEGES_H_
#define BSLS_BSLSD_PRIVILEGES_H_

#include <string>

#include "bsls/framestore/status.h"

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
framestore::Result<CapabilitySets> ReadCapabilitySets(const std::string& status_path);

// Clears the ambient, inheritable, permitted and effective sets (and the
// bounding set where CAP_SETPCAP allows), sets no_new_privs, and checks
// /proc/self/status: kPermissionDenied naming what is left when anything is.
// Must be called while the process has a single thread.
framestore::Status DropAllCapabilities();

// The number of threads of this process (from /proc/self/status).
int ThreadCount();

}  // namespace bsls::bslsd

#endif  // BSLS_BSLSD_PRIVILEGES_H_
