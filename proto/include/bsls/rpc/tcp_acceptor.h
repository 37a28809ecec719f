// The TCP front door of both services (bslsd, bsls-processd): the service
// accepts its TCP connections itself and hands each to its gRPC server
// through grpc::experimental::ExternalConnectionAcceptor, which runs the
// TLS handshake (or none, for plain loopback) as if gRPC had accepted it.
// What gRPC 1.51 does not do is done before:
//  - connections open at once, in all and per peer address
//    (listen.max_tcp_connections, listen.max_tcp_connections_per_peer);
//    one beyond either is closed as soon as it is accepted, and refusals
//    are logged at most once a second;
//  - out of descriptors (EMFILE, ENFILE), the waiting caller is shed
//    through a descriptor kept spare for it and the loop waits a moment
//    instead of spinning.
// A peer that opens a connection and never finishes the handshake holds its
// slot only until gRPC's handshake deadline (listen.handshake_timeout_ms,
// rpc::Http2Limits) closes it. gRPC closes a connection without telling:
// the acceptor recognises a handed-over descriptor by its socket's inode and
// forgets those that no longer are that socket.
//
// Thread-safety: Create, Start and Stop from one thread; the counters from
// any thread. The hand-over function runs on the accept thread.
#ifndef BSLS_RPC_TCP_ACCEPTOR_H_
#define BSLS_RPC_TCP_ACCEPTOR_H_

#include <grpcpp/server_builder.h>
#include <sys/types.h>

#include <atomic>
#include <chrono>
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <string>
#include <thread>

#include "bsls/rpc/server_limits.h"

namespace bsls::rpc {

// Where the socket listens and the limits on its connections.
struct TcpAcceptorOptions {
  std::string address;  // HOST:PORT or [IPv6]:PORT; port 0 picks a free one
  int backlog = 64;
  ConnectionLimits connections;  // max_tcp_connections, max_tcp_connections_per_peer
};

class TcpAcceptor {
 public:
  // Takes a connection (the descriptor is its own from then on) and the
  // listening socket's descriptor.
  using HandOver = std::function<void(int fd, int listener_fd)>;

  // Binds and listens on options.address (the first address it resolves
  // to); nullptr with `error` naming the address and the reason when it
  // cannot.
  static std::unique_ptr<TcpAcceptor> Create(const TcpAcceptorOptions& options, std::string* error);
  // Stops (see Stop) and closes the socket.
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
  // Connections handed over so far.
  std::uint64_t accepted() const { return accepted_; }
  // Connections shed for want of descriptors (EMFILE, ENFILE).
  std::uint64_t shed() const { return shed_; }
  // Connections closed at once because their peer address or everyone
  // together had as many open as allowed.
  std::uint64_t refused() const { return refused_; }

 private:
  // A connection handed over: its socket's inode and its peer's address.
  struct Handed {
    ino_t inode;
    std::string peer;
  };

  TcpAcceptor(TcpAcceptorOptions options, int fd, int port);
  void AcceptLoop(const HandOver& hand_over);
  // Sheds the waiting connection through the spare descriptor and waits a
  // moment; false when Stop was asked meanwhile.
  bool ShedAndWait();
  // Forgets the connections closed since (accept thread only).
  void ForgetClosed();
  // Why one more connection from `peer` would exceed a limit ("" when it would not).
  std::string OverLimit(const std::string& peer) const;
  // Logs a refusal, at most once a second with the count since the last line.
  void LogRefusal(const std::string& peer, const std::string& why);

  TcpAcceptorOptions options_;
  int fd_ = -1;
  int port_ = 0;
  int wake_[2] = {-1, -1};  // a pipe that wakes the accept loop to stop
  int spare_ = -1;          // /dev/null, given up to shed a connection at EMFILE
  std::thread thread_;
  std::atomic<std::uint64_t> accepted_{0};
  std::atomic<std::uint64_t> shed_{0};
  std::atomic<std::uint64_t> refused_{0};
  std::map<int, Handed> handed_;  // by descriptor; accept thread only
  std::uint64_t refused_unlogged_ = 0;
  std::chrono::steady_clock::time_point last_refusal_log_{};
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
