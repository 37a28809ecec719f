// The accept loop both front doors share (rpc::UnixAcceptor, rpc::TcpAcceptor):
// they make their listening sockets and say how to name a connection's peer
// (the uid for a Unix socket, the address for TCP); this loop does the rest:
//  - connections open at once, in all and per peer name; one beyond either
//    is closed as soon as it is accepted, and refusals are logged at most
//    once a second with the count since the last line;
//  - out of descriptors (EMFILE, ENFILE), the waiting caller is shed
//    through a descriptor kept spare for it and the loop waits a moment
//    instead of spinning.
// gRPC closes a connection without telling: the acceptor recognises a
// handed-over descriptor by its socket's inode and forgets those that no
// longer are that socket.
//
// Thread-safety: Create, Start and Stop from one thread; the counters from
// any thread. NamePeer and HandOver run on the accept thread.
#ifndef BSLS_RPC_SRC_ACCEPTOR_H_
#define BSLS_RPC_SRC_ACCEPTOR_H_

#include <sys/socket.h>
#include <sys/types.h>

#include <atomic>
#include <chrono>
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <thread>
#include <vector>

namespace bsls::rpc {

// A connection's peer as the limits count it.
struct Peer {
  std::string name;     // what the per-peer limit counts by ("uid 1000", "127.0.0.1")
  ucred credentials{};  // the peer process (SO_PEERCRED; Unix sockets only)
};

// Connections open at once, and the configuration keys that set them (for
// the refusal messages).
struct AcceptLimits {
  int max_connections = 128;
  std::string max_connections_key;  // e.g. "listen.max_connections"
  int max_per_peer = 32;
  std::string max_per_peer_key;  // e.g. "listen.max_connections_per_user"
};

class Acceptor {
 public:
  // The peer of an accepted connection; nullopt closes the connection.
  using NamePeer = std::function<std::optional<Peer>(int fd)>;
  // Takes a connection (the descriptor is its own from then on), the
  // listening socket it came through and its peer; false when it had to
  // close the connection for want of descriptors (the loop then backs off
  // as at EMFILE and counts it shed).
  using HandOver = std::function<bool(int fd, int listener_fd, const Peer& peer)>;

  // Accepts on `listeners` (bound, listening, non-blocking; owned from here
  // on, closed by the destructor or when Create fails), named `where` in
  // logs. nullptr with `error` saying why when the stop pipe or the spare
  // descriptor cannot be had.
  static std::unique_ptr<Acceptor> Create(std::vector<int> listeners, std::string where,
                                          AcceptLimits limits, NamePeer name_peer,
                                          std::string* error);
  // Stops (see Stop) and closes the listening sockets.
  ~Acceptor();
  Acceptor(const Acceptor&) = delete;
  Acceptor& operator=(const Acceptor&) = delete;

  // Starts accepting on a thread of its own; each connection within the
  // limits goes to `hand_over`.
  void Start(HandOver hand_over);
  // Stops accepting (connections already handed over stay); true when the
  // loop was running.
  bool Stop();

  // The listening sockets, in the order given to Create.
  const std::vector<int>& listeners() const { return listeners_; }
  // Connections handed over so far.
  std::uint64_t accepted() const { return accepted_; }
  // Connections shed for want of descriptors (EMFILE, ENFILE).
  std::uint64_t shed() const { return shed_; }
  // Connections closed at once because their peer or everyone together had
  // as many open as allowed.
  std::uint64_t refused() const { return refused_; }

 private:
  // A connection handed over: its socket's inode and its peer's name.
  struct Handed {
    ino_t inode;
    std::string peer;
  };

  Acceptor(std::vector<int> listeners, std::string where, AcceptLimits limits, NamePeer name_peer);
  void AcceptLoop(const HandOver& hand_over);
  // Accepts one connection waiting on `listener` and hands it over if it is
  // within the limits; false when the loop is to end (Stop asked).
  bool AcceptOne(int listener, const HandOver& hand_over);
  // Sheds the connection waiting on `listener` through the spare descriptor
  // and waits a moment; false when Stop was asked meanwhile.
  bool ShedAndWait(int listener);
  // Forgets the connections closed since (accept thread only).
  void ForgetClosed();
  // Why one more connection from `peer` would exceed a limit ("" when it would not).
  std::string OverLimit(const std::string& peer) const;
  // Logs a refusal, at most once a second with the count since the last line.
  void LogRefusal(const std::string& peer, const std::string& why);

  std::vector<int> listeners_;
  std::string where_;
  AcceptLimits limits_;
  NamePeer name_peer_;
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

}  // namespace bsls::rpc

#endif  // BSLS_RPC_SRC_ACCEPTOR_H_
