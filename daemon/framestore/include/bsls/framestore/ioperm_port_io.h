// Port access through ioperm() and the inb/outb instructions (<sys/io.h>):
// the fastest way (one bus cycle per access, no system call), x86 only. On
// other architectures Open fails with kUnavailable and names /dev/port.
//
// ioperm() needs CAP_SYS_RAWIO and is refused with EPERM under kernel
// lockdown. The permission bitmap belongs to the CALLING THREAD and to
// threads it creates afterwards; an access from another thread would fault
// (SIGSEGV), so Inb/Outb check the thread and, from any thread but the
// opening one, read 0xFF and record kInternal in status() instead of
// touching the port.
// The permission survives dropping capabilities; it is released (ioperm
// off) by the destructor when run on the owning thread.
//
// Thread-safety: use only from the thread that called Open.
#ifndef BSLS_FRAMESTORE_IOPERM_PORT_IO_H_
#define BSLS_FRAMESTORE_IOPERM_PORT_IO_H_

#include <memory>
#include <string>
#include <thread>

#include "bsls/framestore/port_io.h"

namespace bsls::framestore {

class IopermPortIo final : public PortIo {
 public:
  // Grants this thread access to `range` with ioperm(). kPermissionDenied for
  // EPERM (says whether CAP_SYS_RAWIO is missing or the kernel is locked
  // down), kInvalidArgument for a bad range, kUnavailable off x86.
  static Result<std::unique_ptr<IopermPortIo>> Open(PortRange range);
  ~IopermPortIo() override;
  IopermPortIo(const IopermPortIo&) = delete;
  IopermPortIo& operator=(const IopermPortIo&) = delete;

  std::uint8_t Inb(std::uint32_t port) override;
  void Outb(std::uint32_t port, std::uint8_t value) override;
  PortRange range() const override { return range_; }
  Status status() const override { return status_; }
  std::string Describe() const override { return "ioperm"; }

 private:
  explicit IopermPortIo(PortRange range);
  bool OnOwnerThread(std::uint32_t port);

  PortRange range_;
  std::thread::id owner_;
  Status status_;
};

}  // namespace bsls::framestore

#endif  // BSLS_FRAMESTORE_IOPERM_PORT_IO_H_
