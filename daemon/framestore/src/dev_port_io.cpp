#include "bsls/framestore/dev_port_io.h"

#include <fcntl.h>
#include <unistd.h>

#include <cassert>
#include <cerrno>
#include <cstdio>
#include <cstring>

#include "privilege.h"

namespace bsls::framestore {
namespace {

std::string ErrnoName(int err) {
  switch (err) {
    case EPERM:
      return "EPERM";
    case EACCES:
      return "EACCES";
    case ENOENT:
      return "ENOENT";
    case ENXIO:
      return "ENXIO";
    default:
      return "errno " + std::to_string(err);
  }
}

std::string Hex(std::uint32_t port) {
  char text[16];
  std::snprintf(text, sizeof text, "0x%X", port);
  return text;
}

}  // namespace

Result<std::unique_ptr<DevPortIo>> DevPortIo::Open(PortRange range, std::string path) {
  std::string error;
  if (!range.IsValid(&error)) return Status(ErrorCode::kInvalidArgument, error);
  const int fd = ::open(path.c_str(), O_RDWR | O_CLOEXEC);
  if (fd < 0) {
    const int err = errno;
    const std::string what = "cannot open " + path + " for ports " + range.ToString() + ": " +
                             std::strerror(err) + " (" + ErrnoName(err) + "): ";
    switch (err) {
      case EPERM:
        return Status(ErrorCode::kPermissionDenied, what + internal::ExplainEperm());
      case EACCES:
        return Status(ErrorCode::kPermissionDenied,
                      what +
                          "the file is root:kmem mode 0640; bslsd opens it as root with "
                          "CAP_SYS_RAWIO before dropping privileges");
      case ENOENT:
        return Status(ErrorCode::kUnavailable,
                      what +
                          "the kernel has no CONFIG_DEVPORT or the device is hidden from "
                          "this mount namespace (systemd PrivateDevices=/DeviceAllow=); "
                          "try port access 'ioperm' on x86");
      case ENXIO:
      case ENODEV:
        return Status(ErrorCode::kUnavailable,
                      what +
                          "the kernel has no /dev/port driver (CONFIG_DEVPORT is off); try "
                          "port access 'ioperm' on x86");
      default:
        return Status(ErrorCode::kUnavailable, what + "no port access");
    }
  }
  return std::unique_ptr<DevPortIo>(new DevPortIo(fd, range, std::move(path)));
}

DevPortIo::DevPortIo(int fd, PortRange range, std::string path)
    : fd_(fd), range_(range), path_(std::move(path)) {}

DevPortIo::~DevPortIo() { ::close(fd_); }

std::uint8_t DevPortIo::Inb(std::uint32_t port) {
  if (!range_.Contains(port)) {
    assert(false && "DevPortIo::Inb outside the opened range");
    Fail(Status(ErrorCode::kInternal,
                "read of port " + Hex(port) + " outside the opened range " + range_.ToString()));
    return 0xFF;
  }
  std::uint8_t value = 0xFF;
  const ssize_t n = ::pread(fd_, &value, 1, static_cast<off_t>(port));
  if (n != 1) {
    const int err = errno;
    Fail(Status(ErrorCode::kUnavailable,
                "read of port " + Hex(port) + " through " + path_ +
                    " failed: " + (n < 0 ? std::strerror(err) : "short read")));
    return 0xFF;
  }
  return value;
}

void DevPortIo::Outb(std::uint32_t port, std::uint8_t value) {
  if (!range_.Contains(port)) {
    assert(false && "DevPortIo::Outb outside the opened range");
    Fail(Status(ErrorCode::kInternal,
                "write of port " + Hex(port) + " outside the opened range " + range_.ToString()));
    return;
  }
  const ssize_t n = ::pwrite(fd_, &value, 1, static_cast<off_t>(port));
  if (n != 1) {
    const int err = errno;
    Fail(Status(ErrorCode::kUnavailable,
                "write of port " + Hex(port) + " through " + path_ +
                    " failed: " + (n < 0 ? std::strerror(err) : "short write")));
  }
}

Status DevPortIo::status() const {
  std::lock_guard lock(mutex_);
  return status_;
}

void DevPortIo::Fail(Status status) {
  std::lock_guard lock(mutex_);
  if (status_.ok()) status_ = std::move(status);
}

}  // namespace bsls::framestore
