// The Unix-socket front door of bslsd. gRPC C++ does not expose the peer's
// credentials, so the daemon accepts local connections itself: it reads the
// peer's uid with SO_PEERCRED, maps it to a role, remembers the caller under
// the connection's gRPC peer name ("fd:<n>") and only then hands the socket
// to the gRPC server (grpc::AddInsecureChannelFromFd).
//
// A connection's file descriptor stays open until gRPC has finished every
// call on it (the transport owns the endpoint, each call holds the
// transport), so a peer name cannot be reused by a new connection while a
// call of the old one can still look it up.
//
// Thread-safety: PeerRegistry is safe from any thread; UnixListener's
// Start/Stop are called from one thread.
#ifndef BSLS_SERVICE_UNIX_LISTENER_H_
#define BSLS_SERVICE_UNIX_LISTENER_H_

#include <sys/types.h>

#include <atomic>
#include <chrono>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>

#include "bsls/framestore/status.h"
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

// Where and how the socket is created.
struct UnixListenerOptions {
  std::string path;           // socket path; its directory must exist
  mode_t mode = 0660;         // permissions of the socket file
  std::optional<gid_t> group; // owning group of the socket file (else the daemon's)
  int backlog = 64;
  // Connections open at once (handed to gRPC and not yet closed by it), in
  // all and per peer uid; a connection beyond either is closed as soon as
  // it is accepted, so that one user cannot take every descriptor.
  int max_connections = 128;
  int max_connections_per_user = 32;
};

class UnixListener {
 public:
  // Binds and listens on options.path (a stale socket file left by a dead
  // daemon is replaced; a live one is kAlreadyExists).
  static framestore::Result<std::unique_ptr<UnixListener>> Create(const UnixListenerOptions& options);
  ~UnixListener();
  UnixListener(const UnixListener&) = delete;
  UnixListener& operator=(const UnixListener&) = delete;

  // Starts accepting: each connection's caller is recorded in `registry`
  // with its role from `policy`, then given to `server`. All three must
  // outlive Stop().
  void Start(grpc::Server* server, PeerRegistry* registry, const RolePolicy* policy);
  // Stops accepting (connections already handed over stay with gRPC) and
  // removes the socket file.
  void Stop();
  // The socket path.
  const std::string& path() const { return options_.path; }
  // Connections accepted so far.
  std::uint64_t accepted() const { return accepted_; }
  // Connections shed because the process had no descriptor left for them
  // (EMFILE, ENFILE): each is accepted on a descriptor kept spare for this
  // and closed at once, so that its caller hears at once, and the loop
  // waits a moment before it accepts again instead of spinning.
  std::uint64_t shed() const { return shed_; }
  // Connections closed at once because their user or everyone together had
  // as many open as allowed (options.max_connections*).
  std::uint64_t refused() const { return refused_; }

 private:
  // A connection handed to gRPC: the socket's inode tells whether the
  // descriptor still is that connection (gRPC closes it without telling).
  struct Handed {
    ino_t inode;
    uid_t uid;
  };

  UnixListener(UnixListenerOptions options, int fd);
  void AcceptLoop(grpc::Server* server, PeerRegistry* registry, const RolePolicy* policy);
  // Forgets the connections gRPC has closed since (accept loop only).
  void ForgetClosed();
  // Why a new connection of `uid` would exceed a limit ("" when it would not).
  std::string OverLimit(uid_t uid) const;
  // Logs a refusal, at most once a second with the count since the last line.
  void LogRefusal(uid_t uid, const std::string& why);

  UnixListenerOptions options_;
  int fd_ = -1;
  int wake_[2] = {-1, -1};  // a pipe that wakes the accept loop to stop
  int spare_ = -1;          // /dev/null, given up to shed a connection at EMFILE
  std::thread thread_;
  std::atomic<std::uint64_t> accepted_{0};
  std::atomic<std::uint64_t> shed_{0};
  std::atomic<std::uint64_t> refused_{0};
  std::map<int, Handed> handed_;  // by descriptor; accept loop only
  std::uint64_t refused_unlogged_ = 0;
  std::chrono::steady_clock::time_point last_refusal_log_{};
};

}  // namespace bsls::service

#endif  // BSLS_SERVICE_UNIX_LISTENER_H_
