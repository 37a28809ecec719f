#include "bsls/rpc/http2_guard.h"

#include <fcntl.h>
#include <poll.h>
#include <pthread.h>
#include <signal.h>
#include <spdlog/spdlog.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstring>
#include <utility>

#include "bsls/rpc/tls_session.h"

namespace bsls::rpc {
namespace {

constexpr std::size_t kPrefaceBytes = 24;       // "PRI * HTTP/2.0\r\n\r\nSM\r\n\r\n"
constexpr std::size_t kFrameHeaderBytes = 9;    // length (3), type, flags, stream (4)
constexpr std::size_t kBufferBytes = 64 << 10;  // read ahead per direction and link
constexpr int kThrottledPollMs = 5;             // how soon a waiting link is looked at again

// Frame types that make the server work whatever their size.
bool Costly(unsigned char type) {
  return type == 0x1 /*HEADERS*/ || type == 0x2 /*PRIORITY*/ || type == 0x3 /*RST_STREAM*/ ||
         type == 0x4 /*SETTINGS*/ || type == 0x6 /*PING*/;
}

std::int64_t NowNs() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(
             std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

// Adds what `per_second` gives since `*refilled_ns` to `*tokens`, up to `burst`.
void Refill(double* tokens, std::int64_t* refilled_ns, int per_second, int burst) {
  const std::int64_t now = NowNs();
  *tokens = std::min<double>(burst, *tokens + (now - *refilled_ns) * 1e-9 * per_second);
  *refilled_ns = now;
}

// Writes what it can of `*bytes` (up to `count`) to `fd` and drops it from
// the front; false when the connection is gone.
bool WriteSome(int fd, std::string* bytes, std::size_t count) {
  const ssize_t n = ::send(fd, bytes->data(), count, MSG_DONTWAIT | MSG_NOSIGNAL);
  if (n < 0) return errno == EAGAIN || errno == EWOULDBLOCK || errno == EINTR;
  bytes->erase(0, static_cast<std::size_t>(n));
  return true;
}

// Reads what `fd` has, up to kBufferBytes in `*bytes`; false at its end or
// on an error.
bool ReadSome(int fd, std::string* bytes) {
  char buffer[16384];
  const std::size_t room = std::min(sizeof buffer, kBufferBytes - bytes->size());
  const ssize_t n = ::recv(fd, buffer, room, MSG_DONTWAIT);
  if (n == 0) return false;
  if (n < 0) return errno == EAGAIN || errno == EWOULDBLOCK || errno == EINTR;
  bytes->append(buffer, static_cast<std::size_t>(n));
  return true;
}

// Whether the side polled in `fd` has gone while its bytes are not being
// read (its buffer is full): a read would find its end, poll would not wait.
bool HungUp(const pollfd& fd) {
  return (fd.revents & (POLLHUP | POLLERR | POLLNVAL)) != 0 && (fd.events & POLLIN) == 0;
}

}  // namespace

// One relayed connection.
struct Http2Guard::Link {
  int client = -1;
  int inner = -1;                   // the guard's end of the pair; gRPC has the other
  int grpc_end = -1;                // the other end while it waits for a verified handshake
  HandOver hand_over;               // TLS: who takes grpc_end once the client is verified
  std::unique_ptr<TlsSession> tls;  // TLS ended here; none for plaintext
  std::int64_t handshake_deadline_ns = 0;
  bool want_read = false;    // TLS: a step waits for the client to be readable
  bool want_write = false;   // TLS: a step waits for the client to be writable
  std::string up;            // client to gRPC, read and not yet written
  std::size_t admitted = 0;  // bytes at the front of `up` let through
  std::string down;          // gRPC to client, read and not yet written
  std::size_t preface_left = kPrefaceBytes;
  std::size_t payload_left = 0;  // payload of the frame being let through
  bool waiting = false;          // its next frame waits for a token
  double tokens = 0;
  std::int64_t refilled_ns = 0;

  // Whether gRPC has its end (always without TLS).
  bool handed() const { return grpc_end < 0; }
  // Whether the client has said it speaks HTTP/2 (its preface is through).
  bool begun() const { return handed() && preface_left == 0; }

  ~Link() {
    if (tls) tls->Close();
    for (const int fd : {client, inner, grpc_end})
      if (fd >= 0) ::close(fd);
  }
};

Http2Guard::Http2Guard(const Http2GuardLimits& limits, std::shared_ptr<const TlsServerContext> tls,
                       int handshake_timeout_ms)
    : limits_(limits),
      tls_(std::move(tls)),
      handshake_timeout_ms_(handshake_timeout_ms),
      total_tokens_(limits.total_burst),
      total_refilled_ns_(NowNs()) {}

std::unique_ptr<Http2Guard> Http2Guard::Create(const Http2GuardLimits& limits, std::string* error,
                                               std::shared_ptr<const TlsServerContext> tls,
                                               int handshake_timeout_ms) {
  std::unique_ptr<Http2Guard> guard(new Http2Guard(limits, std::move(tls), handshake_timeout_ms));
  if (::pipe2(guard->wake_, O_CLOEXEC | O_NONBLOCK) != 0) {
    *error = std::string("HTTP/2 guard: pipe: ") + std::strerror(errno);
    return nullptr;
  }
  return guard;
}

void Http2Guard::Start() {
  if (!thread_.joinable()) thread_ = std::thread([this] { Relay(); });
}

Http2Guard::~Http2Guard() {
  stopping_ = true;
  const char byte = 0;
  [[maybe_unused]] const ssize_t n = ::write(wake_[1], &byte, 1);
  if (thread_.joinable()) thread_.join();
  for (int& end : wake_)
    if (end >= 0) ::close(end);
}

bool Http2Guard::Guard(int client, HandOver hand_over, std::string* error) {
  int pair[2];
  if (::socketpair(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC | SOCK_NONBLOCK, 0, pair) != 0) {
    *error = std::string("HTTP/2 guard: socketpair: ") + std::strerror(errno);
    ::close(client);
    return false;
  }
  auto link = std::make_unique<Link>();
  link->client = client;
  link->inner = pair[0];
  link->tokens = limits_.burst;
  link->refilled_ns = NowNs();
  link->handshake_deadline_ns = link->refilled_ns + std::int64_t{handshake_timeout_ms_} * 1000000;
  if (tls_) {
    link->tls = std::make_unique<TlsSession>(*tls_, client);
    link->grpc_end = pair[1];
    link->hand_over = std::move(hand_over);
  } else {
    hand_over(pair[1], "");
  }
  {
    std::lock_guard lock(mutex_);
    incoming_.push_back(std::move(link));
  }
  ++relayed_;
  const char byte = 0;
  [[maybe_unused]] const ssize_t n = ::write(wake_[1], &byte, 1);
  return true;
}

void Http2Guard::StopHandingOver() {
  std::lock_guard lock(hand_over_mutex_);
  handing_over_ = false;
}

std::size_t Http2Guard::relayed() const { return relayed_; }

void Http2Guard::Relay() {
  // OpenSSL writes to the client's socket without MSG_NOSIGNAL: a client
  // gone would raise SIGPIPE, which ends the process. Blocked on this
  // thread, the signal stays pending here and the write fails with EPIPE.
  sigset_t pipe;
  sigemptyset(&pipe);
  sigaddset(&pipe, SIGPIPE);
  pthread_sigmask(SIG_BLOCK, &pipe, nullptr);
  std::vector<pollfd> fds;
  while (!stopping_) {
    {
      std::lock_guard lock(mutex_);
      for (auto& link : incoming_) links_.push_back(std::move(link));
      incoming_.clear();
    }
    // Per link: the client, then gRPC's end; the wake pipe last.
    fds.clear();
    int timeout_ms = -1;
    const std::int64_t now = NowNs();
    for (const auto& link : links_) {
      const bool room_up = link->up.size() < kBufferBytes;
      short client_events = 0;
      if (!link->handed()) {
        // Handshaking: the direction the handshake waits for.
        client_events = link->want_write ? POLLOUT : POLLIN;
      } else {
        client_events =
            static_cast<short>(((room_up || link->want_read) ? POLLIN : 0) |
                               ((!link->down.empty() || link->want_write) ? POLLOUT : 0));
      }
      if (!link->begun()) {  // woken at its deadline
        const std::int64_t left_ms =
            std::max<std::int64_t>((link->handshake_deadline_ns - now) / 1000000 + 1, 0);
        timeout_ms = static_cast<int>(timeout_ms < 0 ? left_ms
                                                     : std::min<std::int64_t>(left_ms, timeout_ms));
      }
      fds.push_back({link->client, client_events, 0});
      fds.push_back({link->inner,
                     static_cast<short>((link->down.size() < kBufferBytes ? POLLIN : 0) |
                                        (link->admitted > 0 ? POLLOUT : 0)),
                     0});
      // Decrypted bytes waiting inside TLS wake no poll: look again at once.
      if (link->handed() && link->tls && room_up && link->tls->buffered()) timeout_ms = 0;
      if (link->waiting)
        timeout_ms = timeout_ms < 0 ? kThrottledPollMs : std::min(timeout_ms, kThrottledPollMs);
    }
    fds.push_back({wake_[0], POLLIN, 0});
    if (::poll(fds.data(), fds.size(), timeout_ms) < 0 && errno != EINTR) break;
    if (fds.back().revents != 0) {
      char drain[64];
      while (::read(wake_[0], drain, sizeof drain) > 0) {
      }
    }
    std::size_t kept = 0;
    const std::int64_t polled = NowNs();
    for (std::size_t i = 0; i < links_.size(); ++i) {
      Link& link = *links_[i];
      const bool active = fds[2 * i].revents != 0 || fds[2 * i + 1].revents != 0 ||
                          (link.handed() && link.tls && link.tls->buffered());
      const bool keep = !HungUp(fds[2 * i]) && !HungUp(fds[2 * i + 1]) &&
                        (!(active || link.waiting) || Pump(link));
      const bool late = keep && !link.begun() && polled >= link.handshake_deadline_ns;
      if (late)
        LogRefusal(std::string(link.handed() ? "no HTTP/2 preface" : "no TLS handshake") +
                   " within " + std::to_string(handshake_timeout_ms_) + " ms");
      if (!keep || late) {
        if (late || !link.handed()) ++refused_;
        links_[i].reset();  // closes both ends
        --relayed_;
        continue;
      }
      links_[kept++] = std::move(links_[i]);
    }
    links_.resize(kept);
  }
  relayed_ -= links_.size();
  links_.clear();
}

bool Http2Guard::Handshake(Link& link) {
  link.want_read = link.want_write = false;
  const TlsSession::Step step = link.tls->Handshake();
  if (step == TlsSession::Step::kDone) {
    std::lock_guard lock(hand_over_mutex_);
    if (!handing_over_) return false;  // the server is going: closed (and counted refused)
    const int fd = std::exchange(link.grpc_end, -1);
    link.hand_over(fd, link.tls->common_name());
    return true;
  }
  if (Goes(link, step)) return true;  // the handshake waits for the client
  LogRefusal(step == TlsSession::Step::kClosed
                 ? "the client closed the connection during the TLS handshake"
                 : link.tls->error());
  return false;
}

bool Http2Guard::Goes(Link& link, TlsSession::Step step) {
  switch (step) {
    case TlsSession::Step::kDone:
      return true;
    case TlsSession::Step::kWantRead:
      link.want_read = true;
      return true;
    case TlsSession::Step::kWantWrite:
      link.want_write = true;
      return true;
    case TlsSession::Step::kClosed:
    case TlsSession::Step::kFailed:
      break;
  }
  return false;
}

bool Http2Guard::ReadClient(Link& link) {
  if (link.up.size() >= kBufferBytes) return true;
  if (!link.tls) return ReadSome(link.client, &link.up);
  link.want_read = false;
  const TlsSession::Step step = link.tls->Read(&link.up, kBufferBytes - link.up.size());
  // Waiting to read is what the link polls for whenever `up` has room:
  // nothing to record (a mark would outlive the room and spin the poll).
  return Goes(link, step == TlsSession::Step::kWantRead ? TlsSession::Step::kDone : step);
}

bool Http2Guard::WriteClient(Link& link) {
  if (link.down.empty()) return true;
  if (!link.tls) return WriteSome(link.client, &link.down, link.down.size());
  link.want_write = false;
  return Goes(link, link.tls->Write(&link.down, link.down.size()));
}

void Http2Guard::LogRefusal(const std::string& why) {
  ++refusals_unlogged_;
  const std::int64_t now = NowNs();
  if (now - last_refusal_log_ns_ < 1000000000) return;
  spdlog::warn("connection closed before it began: {}{}", why,
               refusals_unlogged_ > 1
                   ? " (" + std::to_string(refusals_unlogged_) + " since the last such line)"
                   : std::string());
  refusals_unlogged_ = 0;
  last_refusal_log_ns_ = now;
}

bool Http2Guard::Pump(Link& link) {
  if (!link.handed()) {
    if (!Handshake(link)) return false;
    if (!link.handed()) return true;  // the handshake waits for the client
  }
  const bool client_open = ReadClient(link);
  Admit(link);
  if (link.admitted > 0) {
    const std::size_t before = link.up.size();
    if (!WriteSome(link.inner, &link.up, link.admitted)) return false;
    link.admitted -= before - link.up.size();
  }
  const bool inner_open = link.down.size() >= kBufferBytes || ReadSome(link.inner, &link.down);
  if (!WriteClient(link)) return false;
  // A side that ended ends the link; what gRPC said last went out above if
  // the client was reading.
  return client_open && inner_open;
}

void Http2Guard::Admit(Link& link) {
  const bool was_waiting = link.waiting;
  link.waiting = false;
  while (link.admitted < link.up.size()) {
    const std::size_t available = link.up.size() - link.admitted;
    if (link.preface_left > 0 || link.payload_left > 0) {
      std::size_t& left = link.preface_left > 0 ? link.preface_left : link.payload_left;
      const std::size_t take = std::min(left, available);
      left -= take;
      link.admitted += take;
      continue;
    }
    if (available < kFrameHeaderBytes) return;
    const auto* header = reinterpret_cast<const unsigned char*>(link.up.data() + link.admitted);
    if (Costly(header[3]) && !TakeToken(link)) {
      if (!was_waiting) ++throttled_;
      link.waiting = true;
      return;
    }
    link.payload_left =
        (std::size_t{header[0]} << 16) | (std::size_t{header[1]} << 8) | std::size_t{header[2]};
    link.admitted += kFrameHeaderBytes;
  }
}

bool Http2Guard::TakeToken(Link& link) {
  Refill(&link.tokens, &link.refilled_ns, limits_.frames_per_second, limits_.burst);
  Refill(&total_tokens_, &total_refilled_ns_, limits_.total_frames_per_second, limits_.total_burst);
  if (link.tokens < 1 || total_tokens_ < 1) return false;
  link.tokens -= 1;
  total_tokens_ -= 1;
  return true;
}

}  // namespace bsls::rpc
