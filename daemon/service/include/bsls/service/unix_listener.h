// The Unix-socket front door of bslsd. gRPC C++ does not expose the peer's
// credentials, so the daemon accepts local connections itself
// (rpc::UnixAcceptor, which also limits them): it reads the peer's uid with
// SO_PEERCRED, maps it to a role, remembers the caller under the
// connection's gRPC peer name ("fd:<n>") and only then hands the socket to
// the gRPC server (grpc::AddInsecureChannelFromFd) through rpc::Http2Guard,
// which lets the frames that make gRPC work without bound (new streams,
// resets, pings) through at a limited rate, so that a rapid-reset or ping
// flood cannot grow the daemon's memory.
//
// A connection's file descriptor stays open until gRPC has finished every
// call on it (the transport owns the endpoint, each call holds the
// transport), so a peer name cannot be reused by a new connection while a
// call of the old one can still look it up.
//
// Its TCP door (mutual TLS) records callers the same way, named by their
// certificate's common name, once rpc::Http2Guard has verified them.
//
// Thread-safety: PeerRegistry is safe from any thread; UnixListener's
// Start/Stop are called from one thread.
#ifndef BSLS_SERVICE_UNIX_LISTENER_H_
#define BSLS_SERVICE_UNIX_LISTENER_H_

#include <sys/types.h>

#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>

#include "bsls/common/status.h"
#include "bsls/rpc/tcp_acceptor.h"
#include "bsls/rpc/unix_acceptor.h"
#include "bsls/service/roles.h"

namespace grpc {
class Server;
}

namespace bsls::service {

// The callers of the connections the daemon accepted itself, by gRPC peer name.
class PeerRegistry {
 public:
  // Records `caller` for the connection gRPC will name `peer`.
  void Add(const std::string& peer, Caller caller);
  // The caller of connection `peer`; nullopt for connections not accepted here.
  std::optional<Caller> Find(const std::string& peer) const;
  // Connections recorded (for tests and status).
  std::size_t size() const;

 private:
  mutable std::mutex mutex_;
  std::map<std::string, Caller> callers_;
};

// Where and how the socket is created, and the limits on its connections.
struct UnixListenerOptions {
  std::string path;            // socket path; its directory must exist
  mode_t mode = 0660;          // permissions of the socket file
  std::optional<gid_t> group;  // owning group of the socket file (else the daemon's)
  int backlog = 64;
  rpc::ConnectionLimits connections;
  // Each connection relayed through rpc::Http2Guard with these budgets.
  std::optional<rpc::Http2GuardLimits> http2_guard = rpc::Http2GuardLimits{};
  int handshake_timeout_ms = 10000;  // a client's HTTP/2 preface (with the guard)
};

// bslsd's front door: rpc::UnixAcceptor (limits, descriptor exhaustion,
// one instance per socket) with each caller recorded before gRPC gets the
// connection.
class UnixListener {
 public:
  // Binds and listens on options.path (a stale socket file left by a dead
  // daemon is replaced; a live one is kAlreadyExists).
  static Result<std::unique_ptr<UnixListener>> Create(const UnixListenerOptions& options);
  ~UnixListener();
  UnixListener(const UnixListener&) = delete;
  UnixListener& operator=(const UnixListener&) = delete;

  // Starts accepting: each connection's caller is recorded in `registry`
  // with its role from `policy`, then given to `server` through the guard. All three must
  // outlive Stop().
  void Start(grpc::Server* server, PeerRegistry* registry, const RolePolicy* policy);
  // Stops accepting (connections already handed over stay with gRPC) and
  // removes the socket file if it still is the one Create made.
  void Stop();
  // The socket path.
  const std::string& path() const { return acceptor_->path(); }
  // Connections accepted so far.
  std::uint64_t accepted() const { return acceptor_->accepted(); }
  // Connections shed because the process had no descriptor left for them
  // (EMFILE, ENFILE): each is accepted on a descriptor kept spare for this
  // and closed at once, so that its caller hears at once, and the loop
  // waits a moment before it accepts again instead of spinning.
  std::uint64_t shed() const { return acceptor_->shed(); }
  // Connections closed at once because their user or everyone together had
  // as many open as allowed (options.connections).
  std::uint64_t refused() const { return acceptor_->refused(); }

 private:
  explicit UnixListener(std::unique_ptr<rpc::UnixAcceptor> acceptor);

  std::unique_ptr<rpc::UnixAcceptor> acceptor_;
};

// Starts bslsd's TCP listener (mutual TLS ended by its guard): each verified
// caller is recorded in `registry` under its connection's gRPC peer name,
// named by its certificate's common name with its role from `policy`, and
// only then given to `server`. All three must outlive tcp.Stop().
void StartTcpListener(rpc::TcpListener& tcp, grpc::Server* server, PeerRegistry* registry,
                      const RolePolicy* policy);

}  // namespace bsls::service

#endif  // BSLS_SERVICE_UNIX_LISTENER_H_
