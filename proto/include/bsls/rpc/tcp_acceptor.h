// The TCP front door of both services (bslsd, bsls-processd): the service
// accepts its TCP connections itself and hands each to its gRPC server
// through grpc::experimental::ExternalConnectionAcceptor, which runs the
// TLS handshake (or none, for plain loopback) as if gRPC had accepted it.
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
// A peer that opens a connection and never finishes the handshake holds its
// slot only until gRPC's handshake deadline (listen.handshake_timeout_ms,
// rpc::Http2Limits) closes it.
//
// Thread-safety: Create, Start and Stop from one thread; the counters from
// any thread. The hand-over function runs on the accept thread.
#ifndef BSLS_RPC_TCP_ACCEPTOR_H_
#define BSLS_RPC_TCP_ACCEPTOR_H_

#include <grpcpp/server_builder.h>

#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "bsls/rpc/server_limits.h"

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
  // descriptor of the listening socket it came through.
  using HandOver = std::function<void(int fd, int listener_fd)>;

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

// A server's TCP listener: the acceptor and gRPC's end of the hand-over.
struct TcpListener {
  // In this order: the acceptor's thread stops before gRPC's end goes.
  std::unique_ptr<grpc::experimental::ExternalConnectionAcceptor> to_grpc;
  std::unique_ptr<TcpAcceptor> acceptor;

  // Starts handing accepted connections to the server (after BuildAndStart).
  void Start();
  // Stops accepting; connections already handed over stay.
  void Stop();
};

// Binds options.address and registers it on `builder` with `credentials`
// (mutual TLS, or plain for loopback); throws std::runtime_error naming the
// address and the reason when it cannot bind.
TcpListener ListenTcp(const TcpAcceptorOptions& options,
                      std::shared_ptr<grpc::ServerCredentials> credentials,
                      grpc::ServerBuilder& builder);

}  // namespace bsls::rpc

#endif  // BSLS_RPC_TCP_ACCEPTOR_H_
