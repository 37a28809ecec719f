#include "acceptor.h"

#include <fcntl.h>
#include <poll.h>
#include <spdlog/spdlog.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

namespace bsls::rpc {
namespace {

// How long the accept loop waits after shedding a connection for want of
// descriptors (EMFILE, ENFILE), before it accepts again.
constexpr int kDescriptorBackoffMs = 50;

}  // namespace

Acceptor::Acceptor(std::vector<int> listeners, std::string where, AcceptLimits limits,
                   NamePeer name_peer)
    : listeners_(std::move(listeners)),
      where_(std::move(where)),
      limits_(std::move(limits)),
      name_peer_(std::move(name_peer)) {}

std::unique_ptr<Acceptor> Acceptor::Create(std::vector<int> listeners, std::string where,
                                           AcceptLimits limits, NamePeer name_peer,
                                           std::string* error) {
  std::unique_ptr<Acceptor> acceptor(new Acceptor(std::move(listeners), std::move(where),
                                                  std::move(limits), std::move(name_peer)));
  if (::pipe2(acceptor->wake_, O_CLOEXEC) != 0) {
    *error = std::string("pipe: ") + std::strerror(errno);
    return nullptr;
  }
  acceptor->spare_ = ::open("/dev/null", O_RDONLY | O_CLOEXEC);
  if (acceptor->spare_ < 0) {
    *error = std::string("open /dev/null: ") + std::strerror(errno);
    return nullptr;
  }
  return acceptor;
}

Acceptor::~Acceptor() {
  Stop();
  for (const int fd : listeners_) ::close(fd);
  for (int& end : wake_)
    if (end >= 0) ::close(end);
  if (spare_ >= 0) ::close(spare_);
}

void Acceptor::Start(HandOver hand_over) {
  thread_ = std::thread([this, hand_over = std::move(hand_over)] { AcceptLoop(hand_over); });
}

bool Acceptor::Stop() {
  if (!thread_.joinable()) return false;
  const char byte = 0;
  [[maybe_unused]] const ssize_t n = ::write(wake_[1], &byte, 1);
  thread_.join();
  return true;
}

void Acceptor::AcceptLoop(const HandOver& hand_over) {
  // The listeners, then the stop pipe last.
  std::vector<pollfd> fds;
  for (const int fd : listeners_) fds.push_back({fd, POLLIN, 0});
  fds.push_back({wake_[0], POLLIN, 0});
  for (;;) {
    if (::poll(fds.data(), fds.size(), -1) < 0) {
      if (errno == EINTR) continue;
      spdlog::error("accepting on {} stopped: poll: {}", where_, std::strerror(errno));
      return;
    }
    if (fds.back().revents != 0) return;
    for (std::size_t i = 0; i + 1 < fds.size(); ++i)
      if (fds[i].revents != 0 && !AcceptOne(fds[i].fd, hand_over)) return;
  }
}

bool Acceptor::AcceptOne(int listener, const HandOver& hand_over) {
  const int connection = ::accept4(listener, nullptr, nullptr, SOCK_CLOEXEC | SOCK_NONBLOCK);
  if (connection < 0) {
    if (errno == EMFILE || errno == ENFILE) return ShedAndWait(listener);
    return true;  // EAGAIN, ECONNABORTED: try the next one
  }
  const std::optional<Peer> peer = name_peer_(connection);
  struct stat socket_file {};
  if (!peer || ::fstat(connection, &socket_file) != 0) {
    ::close(connection);
    return true;
  }
  ForgetClosed();
  if (const std::string why = OverLimit(peer->name); !why.empty()) {
    ::close(connection);
    ++refused_;
    LogRefusal(peer->name, why);
    return true;
  }
  handed_[connection] = {socket_file.st_ino, peer->name};
  if (!hand_over(connection, listener, *peer)) {
    handed_.erase(connection);
    ++shed_;
    pollfd wake = {wake_[0], POLLIN, 0};
    return ::poll(&wake, 1, kDescriptorBackoffMs) <= 0;
  }
  ++accepted_;
  return true;
}

bool Acceptor::ShedAndWait(int listener) {
  // Out of descriptors: the waiting connection would keep poll awake and
  // the loop spinning. Shed it through the spare descriptor, then wait.
  if (spare_ >= 0) {
    ::close(spare_);
    const int shed = ::accept4(listener, nullptr, nullptr, SOCK_CLOEXEC);
    if (shed >= 0) {
      ::close(shed);
      ++shed_;
    }
    spare_ = ::open("/dev/null", O_RDONLY | O_CLOEXEC);
  }
  pollfd wake = {wake_[0], POLLIN, 0};
  return ::poll(&wake, 1, kDescriptorBackoffMs) <= 0;
}

void Acceptor::ForgetClosed() {
  for (auto it = handed_.begin(); it != handed_.end();) {
    struct stat now {};
    const bool same =
        ::fstat(it->first, &now) == 0 && S_ISSOCK(now.st_mode) && now.st_ino == it->second.inode;
    it = same ? std::next(it) : handed_.erase(it);
  }
}

std::string Acceptor::OverLimit(const std::string& peer) const {
  if (static_cast<int>(handed_.size()) >= limits_.max_connections)
    return std::to_string(handed_.size()) + " connections are open (" +
           limits_.max_connections_key + " " + std::to_string(limits_.max_connections) + ")";
  int mine = 0;
  for (const auto& [fd, handed] : handed_) mine += handed.peer == peer ? 1 : 0;
  if (mine >= limits_.max_per_peer)
    return peer + " has " + std::to_string(mine) + " connections open (" +
           limits_.max_per_peer_key + " " + std::to_string(limits_.max_per_peer) + ")";
  return "";
}

void Acceptor::LogRefusal(const std::string& peer, const std::string& why) {
  ++refused_unlogged_;
  const auto now = std::chrono::steady_clock::now();
  if (now - last_refusal_log_ < std::chrono::seconds(1)) return;
  spdlog::warn("refused {} connection(s) on {} since the last report; the last from {}: {}",
               refused_unlogged_, where_, peer, why);
  refused_unlogged_ = 0;
  last_refusal_log_ = now;
}

}  // namespace bsls::rpc
