// Port access through the /dev/port character device: one pread or pwrite
// of one byte at file offset == port number (drivers/char/mem.c). Works on
// every architecture whose kernel has CONFIG_DEVPORT. Each access is a system
// call (about 1 us, like an ISA I/O cycle).
//
// Opening needs CAP_SYS_RAWIO (the kernel checks it in open, besides the
// file mode root:kmem 0640) and is refused with EPERM under kernel lockdown.
// The descriptor keeps working after capabilities are dropped.
//
// Thread-safety: Inb/Outb may be called from any thread (pread/pwrite carry
// their own offset); status() is guarded by a mutex.
#ifndef BSLS_FRAMESTORE_DEV_PORT_IO_H_
#define BSLS_FRAMESTORE_DEV_PORT_IO_H_

#include <memory>
#include <mutex>
#include <string>

#include "bsls/framestore/port_io.h"

namespace bsls::framestore {

class DevPortIo final : public PortIo {
 public:
  // Opens `path` (normally /dev/port) read-write for `range`. Errors name the
  // path, the ports and the cause: kPermissionDenied (EPERM, EACCES; says
  // whether CAP_SYS_RAWIO is missing or the kernel is locked down),
  // kUnavailable (ENOENT and the rest), kInvalidArgument (bad range).
  static Result<std::unique_ptr<DevPortIo>> Open(PortRange range, std::string path = "/dev/port");
  ~DevPortIo() override;
  DevPortIo(const DevPortIo&) = delete;
  DevPortIo& operator=(const DevPortIo&) = delete;

  std::uint8_t Inb(std::uint32_t port) override;
  void Outb(std::uint32_t port, std::uint8_t value) override;
  PortRange range() const override { return range_; }
  Status status() const override;
  std::string Describe() const override { return path_; }

 private:
  DevPortIo(int fd, PortRange range, std::string path);
  void Fail(Status status);

  int fd_;
  PortRange range_;
  std::string path_;
  mutable std::mutex mutex_;
  Status status_;
};

}  // namespace bsls::framestore

#endif  // BSLS_FRAMESTORE_DEV_PORT_IO_H_
