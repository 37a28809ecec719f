// The Unix-socket front door of both services (bslsd, bsls-processd): the
// service accepts its local connections itself and hands each to its gRPC
// server (grpc::AddInsecureChannelFromFd), so that what gRPC does not do is
// done before: the peer's credentials (SO_PEERCRED) for bslsd's roles, and
// limits no caller can get around (the accept loop shared with
// rpc::TcpAcceptor, proto/src/acceptor.h):
//  - connections open at once, in all and per peer uid; one beyond either
//    is closed as soon as it is accepted (gRPC 1.51 has no such limit);
//  - out of descriptors (EMFILE, ENFILE), the waiting caller is shed
//    through a descriptor kept spare for it and the loop waits a moment
//    instead of spinning;
//  - optionally (UnixAcceptorOptions::http2_guard), each connection relayed
//    through rpc::Http2Guard, which lets the frames that make gRPC work
//    without bound (new streams, resets, pings) through at a bounded rate;
//    when its socket pair cannot be had the connection is shed as at EMFILE;
//  - one live instance per socket (rpc::ClaimUnixSocketPath), and the
//    socket file is removed on Stop only while it is the one made here.
//
// Thread-safety: Create, Start and Stop from one thread; the counters from
// any thread. The hand-over function runs on the accept thread.
#ifndef BSLS_RPC_UNIX_ACCEPTOR_H_
#define BSLS_RPC_UNIX_ACCEPTOR_H_

#include <sys/socket.h>
#include <sys/types.h>

#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <utility>

#include "bsls/rpc/http2_guard.h"
#include "bsls/rpc/server_limits.h"

namespace bsls::rpc {

class Acceptor;

// Where and how the socket is made, and the limits on its connections.
struct UnixAcceptorOptions {
  std::string path;            // socket path; its directory must exist
  mode_t mode = 0660;          // permissions of the socket file
  std::optional<gid_t> group;  // owning group of the socket file (else the process's)
  int backlog = 64;
  ConnectionLimits connections;  // open at once, in all and per peer uid
  // When set, each connection is relayed through rpc::Http2Guard with these
  // budgets (gRPC gets the guard's end; three descriptors per connection).
  std::optional<Http2GuardLimits> http2_guard;
  // With the guard: a client that has not sent the HTTP/2 preface within
  // this is closed.
  int handshake_timeout_ms = 10000;
};

// Why a socket could not be made.
struct UnixAcceptorError {
  enum class Kind { kInvalidPath, kTaken, kPermissionDenied, kSystem };
  Kind kind = Kind::kSystem;
  std::string message;  // names the path and the reason
};

class UnixAcceptor {
 public:
  // Takes a connection (the descriptor is its own from then on) and the
  // peer's credentials.
  using HandOver = std::function<void(int fd, const ucred& peer)>;

  // Binds and listens on options.path with its mode and group (a stale
  // socket file left by a dead server is replaced; a live one is kTaken).
  // nullptr with `error` filled when it cannot.
  static std::unique_ptr<UnixAcceptor> Create(const UnixAcceptorOptions& options,
                                              UnixAcceptorError* error);
  // Stops (see Stop) and closes the socket.
  ~UnixAcceptor();
  UnixAcceptor(const UnixAcceptor&) = delete;
  UnixAcceptor& operator=(const UnixAcceptor&) = delete;

  // Starts accepting on a thread of its own; each connection within the
  // limits goes to `hand_over`.
  void Start(HandOver hand_over);
  // Stops accepting (connections already handed over stay) and removes the
  // socket file if it still is the one Create made.
  void Stop();

  // The socket path.
  const std::string& path() const { return options_.path; }
  // Connections handed over so far.
  std::uint64_t accepted() const;
  // Connections shed for want of descriptors (EMFILE, ENFILE).
  std::uint64_t shed() const;
  // Connections closed at once because their user or everyone together had
  // as many open as allowed.
  std::uint64_t refused() const;

 private:
  UnixAcceptor(UnixAcceptorOptions options, std::unique_ptr<Http2Guard> guard,
               std::unique_ptr<Acceptor> core, std::optional<std::pair<dev_t, ino_t>> socket_file);

  UnixAcceptorOptions options_;
  // In this order: the accept loop, which hands connections to the guard,
  // stops before the guard goes.
  std::unique_ptr<Http2Guard> guard_;                   // null without options.http2_guard
  std::unique_ptr<Acceptor> core_;                      // the accept loop and its limits
  std::optional<std::pair<dev_t, ino_t>> socket_file_;  // the file Create made
};

}  // namespace bsls::rpc

#endif  // BSLS_RPC_UNIX_ACCEPTOR_H_
