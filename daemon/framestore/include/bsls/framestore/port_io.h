// x86 I/O port access behind one small interface: the ISA framestore driver
// talks to its card only through PortIo, so the same driver code runs on
// /dev/port, on ioperm()+inb/outb, and on the register-level card emulator.
//
// Ports are ABSOLUTE I/O port numbers (0x0000..0xFFFF), not offsets.
//
// Errors: Inb/Outb never fail loudly on the hot path. A failed access reads
// 0xFF (what a floating ISA bus gives) and the first failure is kept in
// status(), which the driver checks at the end of each step. Accessing a port
// outside range() is a bug of the caller (asserted; 0xFF and kInternal in
// release builds).
//
// Privilege: the real implementations need CAP_SYS_RAWIO only to open; the
// open descriptor (/dev/port) or the granted I/O bitmap (ioperm) survives
// dropping every capability afterwards, so the daemon opens, then drops.
//
// Thread-safety: see each implementation; none is safe for concurrent use
// unless it says so.
#ifndef BSLS_FRAMESTORE_PORT_IO_H_
#define BSLS_FRAMESTORE_PORT_IO_H_

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <string_view>

#include "bsls/common/status.h"

namespace bsls::framestore {

// A contiguous range of I/O ports [first, first + count).
struct PortRange {
  std::uint32_t first = 0;
  std::uint32_t count = 0;

  // True when every port of [first, first + n) lies in the range.
  bool Contains(std::uint32_t port, std::uint32_t n = 1) const {
    return port >= first && n <= count && port - first <= count - n;
  }
  // True when the range is non-empty and inside 0x0000..0xFFFF; otherwise
  // says why in `error`.
  bool IsValid(std::string* error) const;
  // "0x300-0x303".
  std::string ToString() const;
};

// The whole 16-bit x86 I/O space.
inline constexpr PortRange kAllPorts{0, 0x10000};

// Byte access to I/O ports.
class PortIo {
 public:
  virtual ~PortIo() = default;

  // The byte at `port` (must be in range()); 0xFF after an access failure.
  virtual std::uint8_t Inb(std::uint32_t port) = 0;
  // Writes `value` to `port` (must be in range()); failures go to status().
  virtual void Outb(std::uint32_t port, std::uint8_t value) = 0;
  // The ports this object may access.
  virtual PortRange range() const = 0;
  // Ok, or the first failed access (kUnavailable: the device went away).
  virtual Status status() const = 0;
  // For messages: "/dev/port", "ioperm", "ISA card emulator".
  virtual std::string Describe() const = 0;
};

// The ways to reach real I/O ports.
enum class PortAccess {
  kDevPort,  // pread/pwrite on /dev/port at the port's offset; any architecture with /dev/port
  kIoperm,   // ioperm() then inb/outb instructions; x86 only, per thread (see ioperm_port_io.h)
};

// "dev-port" or "ioperm".
std::string_view ToString(PortAccess access);
// Parses the names of ToString; nullopt for anything else.
std::optional<PortAccess> ParsePortAccess(std::string_view text);

// Opens real port access for `range` (needs CAP_SYS_RAWIO). kInvalidArgument
// for a bad range, kPermissionDenied without the privilege or under kernel
// lockdown, kUnavailable when the mechanism does not exist here.
Result<std::unique_ptr<PortIo>> OpenPortIo(PortAccess access, PortRange range);

}  // namespace bsls::framestore

#endif  // BSLS_FRAMESTORE_PORT_IO_H_
