#include "bsls/framestore/ioperm_port_io.h"

#include <cassert>
#include <cerrno>
#include <cstdio>
#include <cstring>

#if defined(__x86_64__) || defined(__i386__)
#include <sys/io.h>
#define BSLS_HAVE_IOPERM 1
#else
#define BSLS_HAVE_IOPERM 0
#endif

#include "privilege.h"

namespace bsls::framestore {
namespace {

std::string Hex(std::uint32_t port) {
  char text[16];
  std::snprintf(text, sizeof text, "0x%X", port);
  return text;
}

}  // namespace

Result<std::unique_ptr<IopermPortIo>> IopermPortIo::Open(PortRange range) {
  std::string error;
  if (!range.IsValid(&error)) return Status(ErrorCode::kInvalidArgument, error);
#if BSLS_HAVE_IOPERM
  if (::ioperm(range.first, range.count, 1) != 0) {
    const int err = errno;
    const std::string what =
        "ioperm(" + range.ToString() + ") failed: " + std::strerror(err) + ": ";
    if (err == EPERM) return Status(ErrorCode::kPermissionDenied, what + internal::ExplainEperm());
    if (err == ENOSYS) {
      return Status(ErrorCode::kUnavailable,
                    what +
                        "this kernel or sandbox does not implement ioperm; use port access "
                        "'dev-port' (/dev/port)");
    }
    if (err == EINVAL) {
      return Status(ErrorCode::kInvalidArgument, what + "the kernel refuses this port range");
    }
    return Status(ErrorCode::kUnavailable, what + "no port access");
  }
  return std::unique_ptr<IopermPortIo>(new IopermPortIo(range));
#else
  return Status(ErrorCode::kUnavailable,
                "ioperm port access for " + range.ToString() +
                    " exists only on x86; use port access 'dev-port' (/dev/port) here");
#endif
}

IopermPortIo::IopermPortIo(PortRange range) : range_(range), owner_(std::this_thread::get_id()) {}

IopermPortIo::~IopermPortIo() {
#if BSLS_HAVE_IOPERM
  if (std::this_thread::get_id() == owner_) ::ioperm(range_.first, range_.count, 0);
#endif
}

bool IopermPortIo::OnOwnerThread(std::uint32_t port) {
  if (!range_.Contains(port)) {
    assert(false && "IopermPortIo access outside the granted range");
    if (status_.ok()) {
      status_ = Status(ErrorCode::kInternal, "access to port " + Hex(port) +
                                                 " outside the granted range " + range_.ToString());
    }
    return false;
  }
  if (std::this_thread::get_id() != owner_) {
    if (status_.ok()) {
      status_ = Status(ErrorCode::kInternal,
                       "port " + Hex(port) +
                           " accessed from a thread that has no ioperm permission (only the "
                           "opening thread and threads it created later have it)");
    }
    return false;
  }
  return true;
}

std::uint8_t IopermPortIo::Inb(std::uint32_t port) {
  if (!OnOwnerThread(port)) return 0xFF;
#if BSLS_HAVE_IOPERM
  return ::inb(static_cast<unsigned short>(port));
#else
  return 0xFF;
#endif
}

void IopermPortIo::Outb(std::uint32_t port, std::uint8_t value) {
  if (!OnOwnerThread(port)) return;
#if BSLS_HAVE_IOPERM
  ::outb(value, static_cast<unsigned short>(port));
#else
  (void)value;
#endif
}

}  // namespace bsls::framestore
