#include "bsls/rpc/http2_guard.h"

#include <fcntl.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstring>

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
  int inner = -1;            // the guard's end of the pair; gRPC has the other
  std::string up;            // client to gRPC, read and not yet written
  std::size_t admitted = 0;  // bytes at the front of `up` let through
  std::string down;          // gRPC to client, read and not yet written
  std::size_t preface_left = kPrefaceBytes;
  std::size_t payload_left = 0;  // payload of the frame being let through
  bool waiting = false;          // its next frame waits for a token
  double tokens = 0;
  std::int64_t refilled_ns = 0;

  ~Link() {
    if (client >= 0) ::close(client);
    if (inner >= 0) ::close(inner);
  }
};

Http2Guard::Http2Guard(const Http2GuardLimits& limits)
    : limits_(limits), total_tokens_(limits.total_burst), total_refilled_ns_(NowNs()) {}

std::unique_ptr<Http2Guard> Http2Guard::Create(const Http2GuardLimits& limits, std::string* error) {
  std::unique_ptr<Http2Guard> guard(new Http2Guard(limits));
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

int Http2Guard::Guard(int client, std::string* error) {
  int pair[2];
  if (::socketpair(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC | SOCK_NONBLOCK, 0, pair) != 0) {
    *error = std::string("HTTP/2 guard: socketpair: ") + std::strerror(errno);
    ::close(client);
    return -1;
  }
  auto link = std::make_unique<Link>();
  link->client = client;
  link->inner = pair[0];
  link->tokens = limits_.burst;
  link->refilled_ns = NowNs();
  {
    std::lock_guard lock(mutex_);
    incoming_.push_back(std::move(link));
  }
  ++relayed_;
  const char byte = 0;
  [[maybe_unused]] const ssize_t n = ::write(wake_[1], &byte, 1);
  return pair[1];
}

std::size_t Http2Guard::relayed() const { return relayed_; }

void Http2Guard::Relay() {
  std::vector<pollfd> fds;
  while (!stopping_) {
    {
      std::lock_guard lock(mutex_);
      for (auto& link : incoming_) links_.push_back(std::move(link));
      incoming_.clear();
    }
    // Per link: the client, then gRPC's end; the wake pipe last.
    fds.clear();
    bool any_waiting = false;
    for (const auto& link : links_) {
      const bool room_up = link->up.size() < kBufferBytes;
      fds.push_back(
          {link->client,
           static_cast<short>((room_up ? POLLIN : 0) | (link->down.empty() ? 0 : POLLOUT)), 0});
      fds.push_back({link->inner,
                     static_cast<short>((link->down.size() < kBufferBytes ? POLLIN : 0) |
                                        (link->admitted > 0 ? POLLOUT : 0)),
                     0});
      any_waiting = any_waiting || link->waiting;
    }
    fds.push_back({wake_[0], POLLIN, 0});
    if (::poll(fds.data(), fds.size(), any_waiting ? kThrottledPollMs : -1) < 0 && errno != EINTR)
      break;
    if (fds.back().revents != 0) {
      char drain[64];
      while (::read(wake_[0], drain, sizeof drain) > 0) {
      }
    }
    std::size_t kept = 0;
    for (std::size_t i = 0; i < links_.size(); ++i) {
      const bool active = fds[2 * i].revents != 0 || fds[2 * i + 1].revents != 0;
      if (HungUp(fds[2 * i]) || HungUp(fds[2 * i + 1]) ||
          ((active || links_[i]->waiting) && !Pump(*links_[i]))) {
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

bool Http2Guard::Pump(Link& link) {
  const bool client_open = link.up.size() >= kBufferBytes || ReadSome(link.client, &link.up);
  Admit(link);
  if (link.admitted > 0) {
    const std::size_t before = link.up.size();
    if (!WriteSome(link.inner, &link.up, link.admitted)) return false;
    link.admitted -= before - link.up.size();
  }
  const bool inner_open = link.down.size() >= kBufferBytes || ReadSome(link.inner, &link.down);
  if (!link.down.empty() && !WriteSome(link.client, &link.down, link.down.size())) return false;
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
