// Raw connections for the connection-limit tests: to a service's Unix
// socket made as another effective uid (SO_PEERCRED gives the server the
// euid of the connecting process), to its TCP port from one of the loopback
// addresses, whether the server closes one at once, and bytes written to
// and read from one (header only).
#ifndef BSLS_TESTING_RAW_CONNECTIONS_H_
#define BSLS_TESTING_RAW_CONNECTIONS_H_

#include <arpa/inet.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <sys/un.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <string>

namespace bsls::testing {

// A connection to the Unix socket at `path` made with effective uid `uid`
// (0: as this process) and, when `gid` is not 0, effective gid `gid` (the
// socket's group, for a uid that is not its owner), or -1. Switching needs
// root; the test aborts if it cannot switch back.
inline int ConnectUnixAs(uid_t uid, const std::string& path, gid_t gid = 0) {
  if (gid != 0 && ::setegid(gid) != 0) return -1;
  if (uid != 0 && ::seteuid(uid) != 0) {
    if (gid != 0 && ::setegid(0) != 0) std::abort();
    return -1;
  }
  const int fd = ::socket(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC, 0);
  sockaddr_un address{};
  address.sun_family = AF_UNIX;
  std::strncpy(address.sun_path, path.c_str(), sizeof(address.sun_path) - 1);
  const bool connected =
      fd >= 0 && ::connect(fd, reinterpret_cast<const sockaddr*>(&address), sizeof(address)) == 0;
  // The test cannot go on as another user.
  if (uid != 0 && ::seteuid(0) != 0) std::abort();
  if (gid != 0 && ::setegid(0) != 0) std::abort();
  if (!connected) {
    if (fd >= 0) ::close(fd);
    return -1;
  }
  return fd;
}

// A TCP connection to 127.0.0.1:`port` made from the loopback address
// `source` (127.0.0.1, 127.0.0.2...: every 127/8 address is the machine's
// own, so one machine can be several peers), or -1.
inline int ConnectTcpFrom(const std::string& source, int port) {
  const int fd = ::socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
  if (fd < 0) return -1;
  sockaddr_in from{};
  from.sin_family = AF_INET;
  sockaddr_in to{};
  to.sin_family = AF_INET;
  to.sin_port = htons(static_cast<std::uint16_t>(port));
  if (::inet_pton(AF_INET, source.c_str(), &from.sin_addr) != 1 ||
      ::inet_pton(AF_INET, "127.0.0.1", &to.sin_addr) != 1 ||
      ::bind(fd, reinterpret_cast<const sockaddr*>(&from), sizeof(from)) != 0 ||
      ::connect(fd, reinterpret_cast<const sockaddr*>(&to), sizeof(to)) != 0) {
    ::close(fd);
    return -1;
  }
  return fd;
}

// True when the server closes `fd` (end of file or a reset) within `ms`;
// what it sends meanwhile (its HTTP/2 settings) is read and dropped.
inline bool ClosedWithin(int fd, int ms) {
  const auto until = std::chrono::steady_clock::now() + std::chrono::milliseconds(ms);
  for (;;) {
    const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(
        until - std::chrono::steady_clock::now());
    if (left.count() <= 0) return false;
    pollfd wait{fd, POLLIN, 0};
    if (::poll(&wait, 1, static_cast<int>(left.count())) <= 0) continue;
    char buffer[256];
    const ssize_t n = ::recv(fd, buffer, sizeof buffer, MSG_DONTWAIT);
    if (n == 0 || (n < 0 && errno == ECONNRESET)) return true;
  }
}

// Writes all of `bytes` to `fd`; false when the connection fails first.
inline bool SendAll(int fd, const std::string& bytes) {
  std::size_t at = 0;
  while (at < bytes.size()) {
    const ssize_t n = ::send(fd, bytes.data() + at, bytes.size() - at, MSG_NOSIGNAL);
    if (n <= 0) return false;
    at += static_cast<std::size_t>(n);
  }
  return true;
}

// What arrives on `fd` within `ms` (until its end, if sooner); *ended tells
// whether the end came.
inline std::string ReadFor(int fd, int ms, bool* ended = nullptr) {
  std::string bytes;
  const auto until = std::chrono::steady_clock::now() + std::chrono::milliseconds(ms);
  if (ended != nullptr) *ended = false;
  for (;;) {
    const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(
                          until - std::chrono::steady_clock::now())
                          .count();
    if (left <= 0) return bytes;
    pollfd wait{fd, POLLIN, 0};
    if (::poll(&wait, 1, static_cast<int>(left)) <= 0) continue;
    char buffer[65536];
    const ssize_t n = ::recv(fd, buffer, sizeof buffer, MSG_DONTWAIT);
    if (n <= 0) {
      if (ended != nullptr) *ended = true;
      return bytes;
    }
    bytes.append(buffer, static_cast<std::size_t>(n));
  }
}

}  // namespace bsls::testing

#endif  // BSLS_TESTING_RAW_CONNECTIONS_H_
