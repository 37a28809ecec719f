// The TCP front door of both services (bslsd, bsls-processd): the service
// accepts its TCP connections itself and relays each through rpc::Http2Guard,
// which ends mutual TLS (or none, for plain loopback) and lets gRPC have the
// plaintext end once the client is verified (grpc::AddInsecureChannelFromFd).
// Like gRPC's own listener, it binds every address the host name resolves
// to ("localhost" may be both ::1 and 127.0.0.1), all on one port (the one
// the first picked when the address gives port 0); an address that cannot be
// bound is logged and skipped, as gRPC did, and only when none can be bound
// is the listener refused. Where the name resolves to IPv4 and IPv6
// addresses both, the IPv6 sockets are IPv6 only, so that the wildcard
// (":PORT": 0.0.0.0 and ::) binds twice instead of colliding; "[::]:PORT"
// alone stays dual-stack.
// What gRPC 1.51 does not do is done before (the accept loop shared with
// rpc::UnixAcceptor, proto/src/acceptor.h):
//  - connections open at once, in all and per peer address
//    (listen.max_tcp_connections, listen.max_tcp_connections_per_peer);
//    one beyond either is closed as soon as it is accepted, and refusals
//    are logged at most once a second;
//  - out of descriptors (EMFILE, ENFILE), the waiting caller is shed
//    through a descriptor kept spare for it and the loop waits a moment
//    instead of spinning.
// A peer that opens a connection and never finishes the TLS handshake holds
// its slot only until the guard's handshake deadline
// (listen.handshake_timeout_ms) closes it.
//
// Thread-safety: Create, Start and Stop from one thread; the counters from
// any thread. The hand-over function runs on the accept thread.
#ifndef BSLS_RPC_TCP_ACCEPTOR_H_
#define BSLS_RPC_TCP_ACCEPTOR_H_

#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "bsls/rpc/http2_guard.h"
#include "bsls/rpc/server_limits.h"
#include "bsls/rpc/tls.h"

namespace bsls::rpc {

class Acceptor;

// Where the socket listens and the limits on its connections.
struct TcpAcceptorOptions {
  std::string address;  // HOST:PORT or [IPv6]:PORT; port 0 picks a free one
  int backlog = 64;
  ConnectionLimits connections;  // max_tcp_connections, max_tcp_connections_per_peer
  // Refuse to listen when the host resolves to any address that is not
  // loopback (plain TCP: a name must not open it to the network).
  bool loopback_only = false;
};

class TcpAcceptor {
 public:
  // Takes a connection (the descriptor is its own from then on) and the
  // descriptor of the listening socket it came through; false when it had
  // to close the connection for want of descriptors (counted as shed).
  using HandOver = std::function<bool(int fd, int listener_fd)>;

  // Binds and listens on every address options.address resolves to (see
  // above); nullptr with `error` naming the address and the reason when it
  // cannot bind any, or when options.loopback_only and one is not loopback.
  static std::unique_ptr<TcpAcceptor> Create(const TcpAcceptorOptions& options, std::string* error);
  // Stops (see Stop) and closes the sockets.
  ~TcpAcceptor();
  TcpAcceptor(const TcpAcceptor&) = delete;
  TcpAcceptor& operator=(const TcpAcceptor&) = delete;

  // Starts accepting on a thread of its own; each connection within the
  // limits goes to `hand_over`.
  void Start(HandOver hand_over);
  // Stops accepting; connections already handed over stay.
  void Stop();

  // The port listened on (the one picked when the address gave 0).
  int port() const { return port_; }
  // The addresses listened on, as "127.0.0.1:PORT" and "[::1]:PORT".
  const std::vector<std::string>& bound() const { return bound_; }
  // Connections handed over so far.
  std::uint64_t accepted() const;
  // Connections shed for want of descriptors (EMFILE, ENFILE).
  std::uint64_t shed() const;
  // Connections closed at once because their peer address or everyone
  // together had as many open as allowed.
  std::uint64_t refused() const;

 private:
  TcpAcceptor(std::unique_ptr<Acceptor> core, int port, std::vector<std::string> bound);

  std::unique_ptr<Acceptor> core_;  // the accept loop and its limits
  int port_ = 0;
  std::vector<std::string> bound_;
};

// How a server's TCP connections reach it: the acceptor's address and
// limits, the guard's budgets, and mutual TLS (ended by the guard) or none.
struct TcpListenerOptions {
  TcpAcceptorOptions acceptor;
  Http2GuardLimits guard;
  // Mutual TLS; none for plaintext (then acceptor.loopback_only should be set).
  std::optional<TlsFiles> tls;
  int handshake_timeout_ms = 10000;  // a client's TLS handshake and HTTP/2 preface
};

// A server's TCP listener: the acceptor, and the guard every connection is
// relayed through (rpc::Http2Guard: frame budgets, and the TLS end).
struct TcpListener {
  // In this order: the acceptor's thread stops before the guard goes.
  std::unique_ptr<Http2Guard> guard;
  std::unique_ptr<TcpAcceptor> acceptor;

  // Starts accepting: each connection's gRPC end goes to `hand_over`, with
  // the verified common name of its client certificate under TLS (on the
  // guard's thread) or "" without (on the accept thread).
  void Start(Http2Guard::HandOver hand_over);
  // Stops accepting and handing over (a TLS handshake under way is not
  // finished into a hand-over); connections already handed over stay.
  void Stop();
};

// Binds options.acceptor.address and loads the TLS files; throws
// TlsFileError naming the file and the reason, or std::runtime_error naming
// the address and the reason when it cannot bind.
TcpListener ListenTcp(const TcpListenerOptions& options);

}  // namespace bsls::rpc

#endif  // BSLS_RPC_TCP_ACCEPTOR_H_
