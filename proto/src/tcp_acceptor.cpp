#include "bsls/rpc/tcp_acceptor.h"

#include <arpa/inet.h>
#include <fcntl.h>
#include <netdb.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <poll.h>
#include <spdlog/spdlog.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <stdexcept>

namespace bsls::rpc {
namespace {

// How long the accept loop waits after shedding a connection for want of
// descriptors (EMFILE, ENFILE), before it accepts again.
constexpr int kDescriptorBackoffMs = 50;

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

// The port `fd` is bound to.
int BoundPort(int fd) {
  sockaddr_storage bound{};
  socklen_t length = sizeof(bound);
  if (::getsockname(fd, reinterpret_cast<sockaddr*>(&bound), &length) != 0) return 0;
  return ntohs(bound.ss_family == AF_INET6 ? reinterpret_cast<sockaddr_in6*>(&bound)->sin6_port
                                           : reinterpret_cast<sockaddr_in*>(&bound)->sin_port);
}

}  // namespace

TcpAcceptor::TcpAcceptor(TcpAcceptorOptions options, int fd, int port)
    : options_(std::move(options)), fd_(fd), port_(port) {}

std::unique_ptr<TcpAcceptor> TcpAcceptor::Create(const TcpAcceptorOptions& options,
                                                 std::string* error) {
  const std::string& address = options.address;
  auto fail = [error, &address](const std::string& why) {
    *error = "TCP address '" + address + "': " + why;
    return std::unique_ptr<TcpAcceptor>();
  };
  std::string host, port;
  if (!SplitAddress(address, &host, &port)) return fail("not HOST:PORT");
  addrinfo hints{};
  hints.ai_family = AF_UNSPEC;
  hints.ai_socktype = SOCK_STREAM;
  hints.ai_flags = AI_PASSIVE | AI_NUMERICSERV;
  addrinfo* found = nullptr;
  if (const int rc =
          ::getaddrinfo(host.empty() ? nullptr : host.c_str(), port.c_str(), &hints, &found);
      rc != 0)
    return fail(::gai_strerror(rc));
  const std::unique_ptr<addrinfo, void (*)(addrinfo*)> owned(found, ::freeaddrinfo);
  const int fd = ::socket(found->ai_family, SOCK_STREAM | SOCK_CLOEXEC | SOCK_NONBLOCK, 0);
  if (fd < 0) return fail(Errno("socket"));
  const int on = 1;
  ::setsockopt(fd, SOL_SOCKET, SO_REUSEADDR, &on, sizeof(on));
  if (::bind(fd, found->ai_addr, found->ai_addrlen) != 0 || ::listen(fd, options.backlog) != 0) {
    const std::string why = Errno("bind/listen");
    ::close(fd);
    return fail(why);
  }
  std::unique_ptr<TcpAcceptor> acceptor(new TcpAcceptor(options, fd, BoundPort(fd)));
  if (::pipe2(acceptor->wake_, O_CLOEXEC) != 0) return fail(Errno("pipe"));
  acceptor->spare_ = ::open("/dev/null", O_RDONLY | O_CLOEXEC);
  if (acceptor->spare_ < 0) return fail(Errno("open /dev/null"));
  return acceptor;
}

TcpAcceptor::~TcpAcceptor() {
  Stop();
  if (fd_ >= 0) ::close(fd_);
  for (int& end : wake_)
    if (end >= 0) ::close(end);
  if (spare_ >= 0) ::close(spare_);
}

void TcpAcceptor::Start(HandOver hand_over) {
  thread_ = std::thread([this, hand_over = std::move(hand_over)] { AcceptLoop(hand_over); });
}

void TcpAcceptor::Stop() {
  if (!thread_.joinable()) return;
  const char byte = 0;
  [[maybe_unused]] const ssize_t n = ::write(wake_[1], &byte, 1);
  thread_.join();
}

void TcpAcceptor::AcceptLoop(const HandOver& hand_over) {
  for (;;) {
    pollfd fds[2] = {{fd_, POLLIN, 0}, {wake_[0], POLLIN, 0}};
    if (::poll(fds, 2, -1) < 0) {
      if (errno == EINTR) continue;
      return;
    }
    if (fds[1].revents != 0) return;
    const int connection = ::accept4(fd_, nullptr, nullptr, SOCK_CLOEXEC | SOCK_NONBLOCK);
    if (connection < 0) {
      if ((errno == EMFILE || errno == ENFILE) && !ShedAndWait()) return;
      continue;  // EAGAIN, ECONNABORTED: try the next one
    }
    const std::string peer = PeerAddress(connection);
    struct stat socket_file {};
    if (peer.empty() || ::fstat(connection, &socket_file) != 0) {
      ::close(connection);
      continue;
    }
    ForgetClosed();
    if (const std::string why = OverLimit(peer); !why.empty()) {
      ::close(connection);
      ++refused_;
      LogRefusal(peer, why);
      continue;
    }
    const int on = 1;  // as gRPC's own listener does: no Nagle delay on small frames
    ::setsockopt(connection, IPPROTO_TCP, TCP_NODELAY, &on, sizeof(on));
    handed_[connection] = {socket_file.st_ino, peer};
    ++accepted_;
    hand_over(connection, fd_);
  }
}

bool TcpAcceptor::ShedAndWait() {
  // Out of descriptors: the waiting connection would keep poll awake and
  // the loop spinning. Shed it through the spare descriptor, then wait.
  if (spare_ >= 0) {
    ::close(spare_);
    const int shed = ::accept4(fd_, nullptr, nullptr, SOCK_CLOEXEC);
    if (shed >= 0) {
      ::close(shed);
      ++shed_;
    }
    spare_ = ::open("/dev/null", O_RDONLY | O_CLOEXEC);
  }
  pollfd wake = {wake_[0], POLLIN, 0};
  return ::poll(&wake, 1, kDescriptorBackoffMs) <= 0;
}

void TcpAcceptor::ForgetClosed() {
  for (auto it = handed_.begin(); it != handed_.end();) {
    struct stat now {};
    const bool same =
        ::fstat(it->first, &now) == 0 && S_ISSOCK(now.st_mode) && now.st_ino == it->second.inode;
    it = same ? std::next(it) : handed_.erase(it);
  }
}

std::string TcpAcceptor::OverLimit(const std::string& peer) const {
  const ConnectionLimits& limits = options_.connections;
  if (static_cast<int>(handed_.size()) >= limits.max_tcp_connections)
    return std::to_string(handed_.size()) +
           " TCP connections are open (listen.max_tcp_connections " +
           std::to_string(limits.max_tcp_connections) + ")";
  int mine = 0;
  for (const auto& [fd, handed] : handed_) mine += handed.peer == peer ? 1 : 0;
  if (mine >= limits.max_tcp_connections_per_peer)
    return "the address has " + std::to_string(mine) +
           " connections open (listen.max_tcp_connections_per_peer " +
           std::to_string(limits.max_tcp_connections_per_peer) + ")";
  return "";
}

void TcpAcceptor::LogRefusal(const std::string& peer, const std::string& why) {
  ++refused_unlogged_;
  const auto now = std::chrono::steady_clock::now();
  if (now - last_refusal_log_ < std::chrono::seconds(1)) return;
  spdlog::warn("refused {} TCP connection(s) on {} since the last report; the last from {}: {}",
               refused_unlogged_, options_.address, peer, why);
  refused_unlogged_ = 0;
  last_refusal_log_ = now;
}

void TcpListener::Start() {
  grpc::experimental::ExternalConnectionAcceptor* grpc_end = to_grpc.get();
  acceptor->Start([grpc_end](int fd, int listener_fd) {
    grpc::experimental::ExternalConnectionAcceptor::NewConnectionParameters connection;
    connection.listener_fd = listener_fd;
    connection.fd = fd;
    grpc_end->HandleNewConnection(&connection);
  });
}

void TcpListener::Stop() {
  if (acceptor) acceptor->Stop();
}

TcpListener ListenTcp(const TcpAcceptorOptions& options,
                      std::shared_ptr<grpc::ServerCredentials> credentials,
                      grpc::ServerBuilder& builder) {
  TcpListener listener;
  std::string error;
  listener.acceptor = TcpAcceptor::Create(options, &error);
  if (!listener.acceptor) throw std::runtime_error("listen.tcp: " + error);
  listener.to_grpc = builder.experimental().AddExternalConnectionAcceptor(
      grpc::ServerBuilder::experimental_type::ExternalConnectionType::FROM_FD,
      std::move(credentials));
  return listener;
}

}  // namespace bsls::rpc
