#include "bsls/rpc/unix_socket.h"

#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/un.h>
#include <unistd.h>

#include <cstring>

namespace bsls::rpc {
namespace {

// True when something accepts connections on the Unix socket at `path`
// (false for a stale socket or a path too long for a socket).
bool UnixSocketIsLive(const std::string& path) {
  sockaddr_un address{};
  address.sun_family = AF_UNIX;
  if (path.empty() || path.size() >= sizeof(address.sun_path)) return false;
  std::memcpy(address.sun_path, path.c_str(), path.size() + 1);
  const int probe = ::socket(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC, 0);
  if (probe < 0) return false;
  const bool live =
      ::connect(probe, reinterpret_cast<const sockaddr*>(&address), sizeof(address)) == 0;
  ::close(probe);
  return live;
}

}  // namespace

std::string ClaimUnixSocketPath(const std::string& path) {
  struct stat existing {};
  if (::lstat(path.c_str(), &existing) != 0) return "";
  if (!S_ISSOCK(existing.st_mode)) return path + " exists and is not a socket";
  if (UnixSocketIsLive(path)) return "another live instance serves " + path;
  ::unlink(path.c_str());  // left by a server that died
  return "";
}

}  // namespace bsls::rpc
