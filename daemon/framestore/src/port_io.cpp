#include "bsls/framestore/port_io.h"

#include <cstdio>

#include "bsls/framestore/dev_port_io.h"
#include "bsls/framestore/ioperm_port_io.h"

namespace bsls::framestore {

bool PortRange::IsValid(std::string* error) const {
  if (count == 0) {
    if (error) *error = "port range " + ToString() + " is empty";
    return false;
  }
  if (first > 0xFFFF || count > 0x10000 - first) {
    if (error) *error = "port range " + ToString() + " goes beyond the I/O space 0x0000-0xFFFF";
    return false;
  }
  return true;
}

std::string PortRange::ToString() const {
  char text[32];
  std::snprintf(text, sizeof text, "0x%X-0x%X", first, first + count - (count ? 1 : 0));
  return text;
}

std::string_view ToString(PortAccess access) {
  switch (access) {
    case PortAccess::kDevPort:
      return "dev-port";
    case PortAccess::kIoperm:
      return "ioperm";
  }
  return "unknown";
}

std::optional<PortAccess> ParsePortAccess(std::string_view text) {
  for (PortAccess access : {PortAccess::kDevPort, PortAccess::kIoperm}) {
    if (text == ToString(access)) return access;
  }
  return std::nullopt;
}

Result<std::unique_ptr<PortIo>> OpenPortIo(PortAccess access, PortRange range) {
  switch (access) {
    case PortAccess::kDevPort: {
      auto io = DevPortIo::Open(range);
      if (!io.ok()) return io.status();
      return std::unique_ptr<PortIo>(std::move(io).value());
    }
    case PortAccess::kIoperm: {
      auto io = IopermPortIo::Open(range);
      if (!io.ok()) return io.status();
      return std::unique_ptr<PortIo>(std::move(io).value());
    }
  }
  return Status(ErrorCode::kInvalidArgument, "unknown port access kind");
}

}  // namespace bsls::framestore
