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
// Mutual TLS (the services' TCP listeners) is ended here, not by gRPC, so
// that a caller holding a certificate of the clinic's CA is counted like
// any other: the guard runs each TLS handshake without blocking on its
// relay thread (rpc::TlsSession), verifies the client certificate, and only
// then hands gRPC its plaintext end together with the certificate's common
// name (the caller's identity; gRPC itself sees a plaintext connection). A
// client that has not finished its handshake and sent the HTTP/2 preface
// within the handshake timeout is closed, TLS or not: a peer that connects
// and sends nothing holds a descriptor and a connection slot that long at
// most. Connections closed so are logged at most once a second with their
// count.
//
// Thread-safety: Create and Start from one thread, Guard from any one
// thread (the accept loop), the counters from any thread. The relay runs on
// a thread of its own; connections given before Start wait for it. A TLS
// connection's hand-over runs on the relay thread.
#ifndef BSLS_RPC_HTTP2_GUARD_H_
#define BSLS_RPC_HTTP2_GUARD_H_

#include <atomic>
#include <cstdint>
#include <functional>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "bsls/rpc/tls_session.h"

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
  // Takes gRPC's end of a relayed connection (owned from then on) and the
  // verified common name of its client's certificate ("" without TLS).
  using HandOver = std::function<void(int fd, const std::string& common_name)>;

  // A guard, its relay not started yet (a daemon may still need to be
  // single-threaded), ending TLS on every connection when `tls` is given
  // (the server's certificate, the clients' CA). A client that has not
  // finished its TLS handshake and sent the HTTP/2 connection preface within
  // `handshake_timeout_ms` of Guard is closed. nullptr with `error` naming
  // the reason when its wake pipe cannot be had.
  static std::unique_ptr<Http2Guard> Create(const Http2GuardLimits& limits, std::string* error,
                                            std::shared_ptr<const TlsServerContext> tls = nullptr,
                                            int handshake_timeout_ms = 10000);
  // Stops the relay and closes every connection still relayed (both ends).
  ~Http2Guard();
  Http2Guard(const Http2Guard&) = delete;
  Http2Guard& operator=(const Http2Guard&) = delete;

  // Starts the relay on a thread of its own (once; later calls do nothing).
  void Start();
  // Relays the client connection `client` (owned from now on, closed when
  // either side ends) and gives `hand_over` the descriptor for gRPC in its
  // place: at once without TLS (on this thread), after a verified handshake
  // with TLS (on the relay thread; never when it fails). False with `error`
  // naming the reason (and `client` closed) when no socket pair can be had.
  bool Guard(int client, HandOver hand_over, std::string* error);
  // From its return on no TLS connection is handed over (those finishing
  // their handshake later are closed), so that a server shutting down gets
  // none; connections already handed over stay relayed.
  void StopHandingOver();

  // Connections being relayed.
  std::size_t relayed() const;
  // Times a connection had spent its budget and was made to wait (once per wait).
  std::uint64_t throttled() const { return throttled_; }
  // Connections closed before they began: a failed TLS handshake, an
  // unverified certificate, or no handshake and preface within the timeout.
  std::uint64_t refused() const { return refused_; }

 private:
  struct Link;
  Http2Guard(const Http2GuardLimits& limits, std::shared_ptr<const TlsServerContext> tls,
             int handshake_timeout_ms);
  void Relay();
  // Moves what can move on `link` (handshake, reads, writes, lets frames
  // through); false when the link has ended.
  bool Pump(Link& link);
  // Moves `link`'s TLS handshake on and hands its gRPC end over once the
  // client is verified; false when the handshake failed.
  bool Handshake(Link& link);
  // Records on `link` what a TLS step waits for (the client readable or
  // writable); false when the step ended the connection.
  static bool Goes(Link& link, TlsSession::Step step);
  // Reads what the client sent into link.up; false at its end or on an error.
  bool ReadClient(Link& link);
  // Writes link.down to the client; false when the client is gone.
  bool WriteClient(Link& link);
  // Logs a connection closed before it began, at most once a second with
  // the count since the last line.
  void LogRefusal(const std::string& why);
  // Lets through the frames of `link`'s read bytes its budget allows.
  void Admit(Link& link);
  // Takes one frame from the budgets of `link` and of all; false when either is empty.
  bool TakeToken(Link& link);

  Http2GuardLimits limits_;
  std::shared_ptr<const TlsServerContext> tls_;
  int handshake_timeout_ms_;
  int wake_[2] = {-1, -1};  // written to by Guard (a new link) and the destructor
  std::atomic<bool> stopping_{false};
  std::mutex hand_over_mutex_;                   // held while a TLS connection is handed over
  bool handing_over_ = true;                     // guarded by hand_over_mutex_
  mutable std::mutex mutex_;                     // guards incoming_
  std::vector<std::unique_ptr<Link>> incoming_;  // links given by Guard, not yet polled
  std::vector<std::unique_ptr<Link>> links_;     // relay thread only
  std::atomic<std::size_t> relayed_{0};
  std::atomic<std::uint64_t> throttled_{0};
  std::atomic<std::uint64_t> refused_{0};
  double total_tokens_ = 0;  // relay thread only
  std::int64_t total_refilled_ns_ = 0;
  std::uint64_t refusals_unlogged_ = 0;  // relay thread only
  std::int64_t last_refusal_log_ns_ = 0;
  std::thread thread_;
};

}  // namespace bsls::rpc

#endif  // BSLS_RPC_HTTP2_GUARD_H_
