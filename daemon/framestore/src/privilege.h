// Why an attempt to reach I/O ports was refused: the capability or the
// kernel's lockdown. Internal to the port access implementations.
#ifndef BSLS_FRAMESTORE_SRC_PRIVILEGE_H_
#define BSLS_FRAMESTORE_SRC_PRIVILEGE_H_

#include <string>

namespace bsls::framestore::internal {

// True when CAP_SYS_RAWIO is in this thread's effective set.
bool HasCapSysRawio();
// The kernel lockdown mode ("none", "integrity", "confidentiality"), or an
// empty string when the kernel does not say (no securityfs, no lockdown LSM).
std::string LockdownMode();
// The cause of an EPERM from opening /dev/port or from ioperm(), for messages.
std::string ExplainEperm();

}  // namespace bsls::framestore::internal

#endif  // BSLS_FRAMESTORE_SRC_PRIVILEGE_H_
