#include "privilege.h"

#include <linux/capability.h>
#include <sys/syscall.h>
#include <unistd.h>

#include <fstream>
#include <string>

namespace bsls::framestore::internal {

bool HasCapSysRawio() {
  __user_cap_header_struct header{};
  header.version = _LINUX_CAPABILITY_VERSION_3;
  header.pid = 0;
  __user_cap_data_struct data[_LINUX_CAPABILITY_U32S_3] = {};
  if (syscall(SYS_capget, &header, data) != 0) return false;
  return (data[CAP_TO_INDEX(CAP_SYS_RAWIO)].effective & CAP_TO_MASK(CAP_SYS_RAWIO)) != 0;
}

std::string LockdownMode() {
  // The file reads e.g. "none [integrity] confidentiality"; brackets mark the mode.
  std::ifstream in("/sys/kernel/security/lockdown");
  std::string line;
  if (!in || !std::getline(in, line)) return {};
  const auto open = line.find('[');
  const auto close = line.find(']', open == std::string::npos ? 0 : open);
  if (open == std::string::npos || close == std::string::npos) return {};
  return line.substr(open + 1, close - open - 1);
}

std::string ExplainEperm() {
  const std::string lockdown = LockdownMode();
  if (!lockdown.empty() && lockdown != "none") {
    return "the kernel is locked down (" + lockdown +
           " mode, /sys/kernel/security/lockdown; Secure Boot enables it), which forbids "
           "raw port access to every process; use a kernel without lockdown or the USB "
           "framestore";
  }
  if (!HasCapSysRawio()) {
    return "the process lacks CAP_SYS_RAWIO (run bslsd with AmbientCapabilities="
           "CAP_SYS_RAWIO; it drops the capability once the ports are open)";
  }
  return "refused although CAP_SYS_RAWIO is held: probably kernel lockdown "
         "(/sys/kernel/security/lockdown not readable here) or a seccomp/LSM policy";
}

}  // namespace bsls::framestore::internal
