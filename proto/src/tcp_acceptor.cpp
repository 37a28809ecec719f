#include "bsls/rpc/tcp_acceptor.h"

#include <arpa/inet.h>
#include <netdb.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <spdlog/spdlog.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <optional>
#include <stdexcept>

#include "acceptor.h"
#include "bsls/rpc/tls_session.h"

namespace bsls::rpc {
namespace {

std::string Errno(const std::string& what) { return what + ": " + std::strerror(errno); }

// HOST and PORT of "HOST:PORT" or "[V6]:PORT"; false when there is no port.
bool SplitAddress(const std::string& address, std::string* host, std::string* port) {
  const std::size_t colon = address.rfind(':');
  if (colon == std::string::npos || colon + 1 == address.size()) return false;
  *host = address.substr(0, colon);
  *port = address.substr(colon + 1);
  if (host->size() >= 2 && host->front() == '[' && host->back() == ']')
    *host = host->substr(1, host->size() - 2);
  return true;
}

// The peer's address without its port ("" when it cannot be read).
std::string PeerAddress(int fd) {
  sockaddr_storage peer{};
  socklen_t length = sizeof(peer);
  if (::getpeername(fd, reinterpret_cast<sockaddr*>(&peer), &length) != 0) return "";
  char text[INET6_ADDRSTRLEN] = {};
  const void* bytes =
      peer.ss_family == AF_INET6
          ? static_cast<const void*>(&reinterpret_cast<sockaddr_in6*>(&peer)->sin6_addr)
          : static_cast<const void*>(&reinterpret_cast<sockaddr_in*>(&peer)->sin_addr);
  return ::inet_ntop(peer.ss_family, bytes, text, sizeof(text)) != nullptr ? text : "";
}

// The port of `address` (IPv4 or IPv6).
int PortOf(const sockaddr_storage& address) {
  return ntohs(address.ss_family == AF_INET6
                   ? reinterpret_cast<const sockaddr_in6*>(&address)->sin6_port
                   : reinterpret_cast<const sockaddr_in*>(&address)->sin_port);
}

// Sets the port of `address` (IPv4 or IPv6).
void SetPort(sockaddr_storage* address, int port) {
  const auto network = htons(static_cast<std::uint16_t>(port));
  if (address->ss_family == AF_INET6)
    reinterpret_cast<sockaddr_in6*>(address)->sin6_port = network;
  else
    reinterpret_cast<sockaddr_in*>(address)->sin_port = network;
}

// "127.0.0.1:PORT" or "[::1]:PORT".
std::string AddressText(const sockaddr_storage& address) {
  char text[INET6_ADDRSTRLEN] = {};
  const bool v6 = address.ss_family == AF_INET6;
  const void* bytes =
      v6 ? static_cast<const void*>(&reinterpret_cast<const sockaddr_in6*>(&address)->sin6_addr)
         : static_cast<const void*>(&reinterpret_cast<const sockaddr_in*>(&address)->sin_addr);
  ::inet_ntop(address.ss_family, bytes, text, sizeof(text));
  const std::string port = std::to_string(PortOf(address));
  return v6 ? "[" + std::string(text) + "]:" + port : std::string(text) + ":" + port;
}

// Whether `address` is a loopback address (127/8, ::1).
bool IsLoopback(const sockaddr_storage& address) {
  if (address.ss_family == AF_INET6)
    return IN6_IS_ADDR_LOOPBACK(&reinterpret_cast<const sockaddr_in6*>(&address)->sin6_addr);
  return (ntohl(reinterpret_cast<const sockaddr_in*>(&address)->sin_addr.s_addr) >> 24) == 127;
}

// The distinct IPv4 and IPv6 addresses `host` (empty: the wildcard) and
// `port` resolve to, in the resolver's order; "" or the resolver's reason.
std::string Resolve(const std::string& host, const std::string& port,
                    std::vector<sockaddr_storage>* addresses) {
  addrinfo hints{};
  hints.ai_family = AF_UNSPEC;
  hints.ai_socktype = SOCK_STREAM;
  hints.ai_flags = AI_PASSIVE | AI_NUMERICSERV;
  addrinfo* found = nullptr;
  if (const int rc =
          ::getaddrinfo(host.empty() ? nullptr : host.c_str(), port.c_str(), &hints, &found);
      rc != 0)
    return ::gai_strerror(rc);
  const std::unique_ptr<addrinfo, void (*)(addrinfo*)> owned(found, ::freeaddrinfo);
  for (const addrinfo* entry = found; entry != nullptr; entry = entry->ai_next) {
    if ((entry->ai_family != AF_INET && entry->ai_family != AF_INET6) ||
        entry->ai_addrlen > sizeof(sockaddr_storage))
      continue;
    sockaddr_storage address{};
    std::memcpy(&address, entry->ai_addr, entry->ai_addrlen);
    const bool seen = std::any_of(addresses->begin(), addresses->end(), [&](const auto& known) {
      return AddressText(known) == AddressText(address);
    });
    if (!seen) addresses->push_back(address);
  }
  return addresses->empty() ? "no IPv4 or IPv6 address" : "";
}

// A socket bound to `address` and listening, or -1 with `why` set.
// `v6_only`: an IPv6 socket takes no IPv4 connections (the IPv4 addresses
// have sockets of their own).
int BindOne(const sockaddr_storage& address, bool v6_only, int backlog, std::string* why) {
  const int fd = ::socket(address.ss_family, SOCK_STREAM | SOCK_CLOEXEC | SOCK_NONBLOCK, 0);
  if (fd < 0) {
    *why = Errno("socket");
    return -1;
  }
  const int on = 1;
  ::setsockopt(fd, SOL_SOCKET, SO_REUSEADDR, &on, sizeof(on));
  if (address.ss_family == AF_INET6 && v6_only &&
      ::setsockopt(fd, IPPROTO_IPV6, IPV6_V6ONLY, &on, sizeof(on)) != 0) {
    *why = Errno("IPV6_V6ONLY");
    ::close(fd);
    return -1;
  }
  const socklen_t length =
      address.ss_family == AF_INET6 ? sizeof(sockaddr_in6) : sizeof(sockaddr_in);
  if (::bind(fd, reinterpret_cast<const sockaddr*>(&address), length) != 0 ||
      ::listen(fd, backlog) != 0) {
    *why = Errno("bind/listen");
    ::close(fd);
    return -1;
  }
  return fd;
}

// The port `fd` is bound to.
int BoundPort(int fd) {
  sockaddr_storage bound{};
  socklen_t length = sizeof(bound);
  if (::getsockname(fd, reinterpret_cast<sockaddr*>(&bound), &length) != 0) return 0;
  return ntohs(bound.ss_family == AF_INET6 ? reinterpret_cast<sockaddr_in6*>(&bound)->sin6_port
                                           : reinterpret_cast<sockaddr_in*>(&bound)->sin_port);
}

// A TCP connection's peer, named by its address; nullopt when it cannot
// be read. Small frames go out at once, as with gRPC's own listener.
std::optional<Peer> PeerOfTcpConnection(int fd) {
  Peer peer;
  peer.name = PeerAddress(fd);
  if (peer.name.empty()) return std::nullopt;
  const int on = 1;
  ::setsockopt(fd, IPPROTO_TCP, TCP_NODELAY, &on, sizeof(on));
  return peer;
}

}  // namespace

TcpAcceptor::TcpAcceptor(std::unique_ptr<Acceptor> core, int port, std::vector<std::string> bound)
    : core_(std::move(core)), port_(port), bound_(std::move(bound)) {}

std::unique_ptr<TcpAcceptor> TcpAcceptor::Create(const TcpAcceptorOptions& options,
                                                 std::string* error) {
  const std::string& address = options.address;
  auto fail = [error, &address](const std::string& why) {
    *error = "TCP address '" + address + "': " + why;
    return std::unique_ptr<TcpAcceptor>();
  };
  std::string host, port;
  if (!SplitAddress(address, &host, &port)) return fail("not HOST:PORT");
  std::vector<sockaddr_storage> addresses;
  if (const std::string why = Resolve(host, port, &addresses); !why.empty()) return fail(why);
  const bool both_families = std::any_of(addresses.begin(), addresses.end(),
                                         [](const auto& a) { return a.ss_family == AF_INET; }) &&
                             std::any_of(addresses.begin(), addresses.end(),
                                         [](const auto& a) { return a.ss_family == AF_INET6; });
  std::vector<int> listeners;
  std::vector<std::string> bound, failed;
  int chosen = 0;  // the port of the first socket bound, for the others when asked for 0
  for (sockaddr_storage& each : addresses) {
    if (options.loopback_only && !IsLoopback(each)) {
      for (const int fd : listeners) ::close(fd);
      return fail("resolves to " + AddressText(each) + ", which is not a loopback address");
    }
    if (chosen != 0) SetPort(&each, chosen);
    std::string why;
    const int fd = BindOne(each, both_families, options.backlog, &why);
    if (fd < 0) {
      failed.push_back(AddressText(each) + ": " + why);
      continue;
    }
    if (chosen == 0) chosen = BoundPort(fd);
    listeners.push_back(fd);
    SetPort(&each, chosen);
    bound.push_back(AddressText(each));
  }
  std::string all_failed;
  for (const std::string& line : failed) all_failed += (all_failed.empty() ? "" : "; ") + line;
  if (listeners.empty()) return fail(all_failed);
  if (!failed.empty())
    spdlog::warn("TCP address '{}': listening on {} of its {} addresses; not on {}", address,
                 bound.size(), addresses.size(), all_failed);
  AcceptLimits limits{options.connections.max_tcp_connections, "listen.max_tcp_connections",
                      options.connections.max_tcp_connections_per_peer,
                      "listen.max_tcp_connections_per_peer"};
  std::string why;
  std::unique_ptr<Acceptor> core = Acceptor::Create(std::move(listeners), "tcp:" + address,
                                                    std::move(limits), PeerOfTcpConnection, &why);
  if (!core) return fail(why);
  return std::unique_ptr<TcpAcceptor>(new TcpAcceptor(std::move(core), chosen, std::move(bound)));
}

TcpAcceptor::~TcpAcceptor() { Stop(); }

void TcpAcceptor::Start(HandOver hand_over) {
  core_->Start([hand_over = std::move(hand_over)](int fd, int listener_fd, const Peer&) {
    return hand_over(fd, listener_fd);
  });
}

void TcpAcceptor::Stop() { core_->Stop(); }

std::uint64_t TcpAcceptor::accepted() const { return core_->accepted(); }

std::uint64_t TcpAcceptor::shed() const { return core_->shed(); }

std::uint64_t TcpAcceptor::refused() const { return core_->refused(); }

void TcpListener::Start(Http2Guard::HandOver hand_over) {
  guard->Start();
  acceptor->Start([guard = guard.get(), hand_over = std::move(hand_over)](int fd, int) {
    std::string ignored;  // the only reason: no descriptors for the socket pair
    return guard->Guard(fd, hand_over, &ignored);
  });
}

void TcpListener::Stop() {
  if (acceptor) acceptor->Stop();
  if (guard) guard->StopHandingOver();
}

TcpListener ListenTcp(const TcpListenerOptions& options) {
  std::shared_ptr<const TlsServerContext> tls;
  if (options.tls) tls = TlsServerContext::Create(*options.tls);
  TcpListener listener;
  std::string error;
  listener.guard =
      Http2Guard::Create(options.guard, &error, std::move(tls), options.handshake_timeout_ms);
  if (!listener.guard) throw std::runtime_error("listen.tcp: " + error);
  listener.acceptor = TcpAcceptor::Create(options.acceptor, &error);
  if (!listener.acceptor) throw std::runtime_error("listen.tcp: " + error);
  return listener;
}

}  // namespace bsls::rpc
