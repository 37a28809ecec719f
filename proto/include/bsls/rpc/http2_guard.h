// A guard between plaintext HTTP/2 clients and a gRPC server: each
// connection is relayed through a socket pair whose other end gRPC gets, and
// the frames a client can make the server work for without bound are let
// through at a limited rate: new streams (HEADERS), RST_STREAM, PING,
// SETTINGS and PRIORITY. gRPC 1.51 creates a call for every HEADERS it
// reads, as fast as it reads them, but frees the calls a client resets far
// more slowly, and queues an acknowledgement for every PING: a rapid-reset
// flood took bslsd to 4 GB of resident memory in 10 s, a ping flood to
// 1.4 GB (issue 26; test BslsdHttp2Flood.*). Above its budget a connection
// is not refused but waits: its bytes stay in the kernel, so an ordinary
// client is slowed at worst, while a flood's frames reach gRPC no faster
// than it can free what they make. Budgets: per connection, and for all
// connections together so that many connections are not many budgets.
// Data, WINDOW_UPDATE and continuation frames pass as they come.
//
// The guard reads frame headers only; TLS connections are opaque to it and
// are not guarded (bslsd's TCP listener is mutual TLS: its callers hold a
// certificate of the clinic's CA).
//
// Thread-safety: Create and Start from one thread, Guard from any one
// thread (the accept loop), the counters from any thread. The relay runs on
// a thread of its own; connections given before Start wait for it.
#ifndef BSLS_RPC_HTTP2_GUARD_H_
#define BSLS_RPC_HTTP2_GUARD_H_

#include <atomic>
#include <cstdint>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

namespace bsls::rpc {

// Frames that make the server work (HEADERS, PRIORITY, RST_STREAM,
// SETTINGS, PING) let through per second, and in one burst after a quiet
// while.
struct Http2GuardLimits {
  int frames_per_second = 200;         // per connection
  int burst = 400;                     // per connection
  int total_frames_per_second = 2000;  // all connections together
  int total_burst = 4000;              // all connections together
};

class Http2Guard {
 public:
  // A guard, its relay not started yet (a daemon may still need to be
  // single-threaded); nullptr with `error` naming the reason when its wake
  // pipe cannot be had.
  static std::unique_ptr<Http2Guard> Create(const Http2GuardLimits& limits, std::string* error);
  // Stops the relay and closes every connection still relayed (both ends).
  ~Http2Guard();
  Http2Guard(const Http2Guard&) = delete;
  Http2Guard& operator=(const Http2Guard&) = delete;

  // Starts the relay on a thread of its own (once; later calls do nothing).
  void Start();
  // Relays the client connection `client` (owned from now on, closed when
  // either side ends) and returns the descriptor to hand to gRPC in its
  // place; -1 with `error` naming the reason (and `client` closed) when no
  // socket pair can be had.
  int Guard(int client, std::string* error);

  // Connections being relayed.
  std::size_t relayed() const;
  // Times a connection had spent its budget and was made to wait (once per wait).
  std::uint64_t throttled() const { return throttled_; }

 private:
  struct Link;
  explicit Http2Guard(const Http2GuardLimits& limits);
  void Relay();
  // Moves what can move on `link` (reads, writes, lets frames through);
  // false when the link has ended.
  bool Pump(Link& link);
  // Lets through the frames of `link`'s read bytes its budget allows.
  void Admit(Link& link);
  // Takes one frame from the budgets of `link` and of all; false when either is empty.
  bool TakeToken(Link& link);

  Http2GuardLimits limits_;
  int wake_[2] = {-1, -1};  // written to by Guard (a new link) and the destructor
  std::atomic<bool> stopping_{false};
  mutable std::mutex mutex_;                     // guards incoming_
  std::vector<std::unique_ptr<Link>> incoming_;  // links given by Guard, not yet polled
  std::vector<std::unique_ptr<Link>> links_;     // relay thread only
  std::atomic<std::size_t> relayed_{0};
  std::atomic<std::uint64_t> throttled_{0};
  double total_tokens_ = 0;  // relay thread only
  std::int64_t total_refilled_ns_ = 0;
  std::thread thread_;
};

}  // namespace bsls::rpc

#endif  // BSLS_RPC_HTTP2_GUARD_H_
