#include "bsls/service/unix_listener.h"

#include <fcntl.h>
#include <grpcpp/server.h>
#include <grpcpp/server_posix.h>
#include <poll.h>
#include <pwd.h>
#include <spdlog/spdlog.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/un.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <vector>

#include "bsls/rpc/unix_socket.h"

namespace bsls::service {

using framestore::ErrorCode;
using framestore::Result;
using framestore::Status;

void PeerRegistry::Add(const std::string& peer, Caller caller) {
  std::lock_guard lock(mutex_);
  callers_[peer] = std::move(caller);
}

std::optional<Caller> PeerRegistry::Find(const std::string& peer) const {
  std::lock_guard lock(mutex_);
  auto it = callers_.find(peer);
  if (it == callers_.end()) return std::nullopt;
  return it->second;
}

std::size_t PeerRegistry::size() const {
  std::lock_guard lock(mutex_);
  return callers_.size();
}

namespace {

// How long the accept loop waits after shedding a connection for want of
// descriptors (EMFILE, ENFILE), before it accepts again.
constexpr int kDescriptorBackoffMs = 50;

std::string Errno(const std::string& what) { return what + ": " + std::strerror(errno); }

std::string UserName(uid_t uid) {
  std::vector<char> buffer(16384);
  passwd entry{};
  passwd* found = nullptr;
  if (::getpwuid_r(uid, &entry, buffer.data(), buffer.size(), &found) == 0 && found != nullptr)
    return found->pw_name;
  return "uid" + std::to_string(uid);
}

}  // namespace

UnixListener::UnixListener(UnixListenerOptions options, int fd)
    : options_(std::move(options)), fd_(fd) {}

Result<std::unique_ptr<UnixListener>> UnixListener::Create(const UnixListenerOptions& options) {
  sockaddr_un address{};
  address.sun_family = AF_UNIX;
  if (options.path.empty() || options.path.size() >= sizeof(address.sun_path))
    return Status(ErrorCode::kInvalidArgument,
                  "socket path '" + options.path + "' is empty or longer than " +
                      std::to_string(sizeof(address.sun_path) - 1) + " bytes");
  std::memcpy(address.sun_path, options.path.c_str(), options.path.size() + 1);

  if (const std::string taken = rpc::ClaimUnixSocketPath(options.path); !taken.empty())
    return Status(ErrorCode::kAlreadyExists, "socket path: " + taken);
  const int fd = ::socket(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC | SOCK_NONBLOCK, 0);
  if (fd < 0) return Status(ErrorCode::kUnavailable, Errno("socket(AF_UNIX)"));
  // The file is created with the umask applied; permissions are set next,
  // before anyone is accepted.
  if (::bind(fd, reinterpret_cast<const sockaddr*>(&address), sizeof(address)) != 0) {
    Status status(errno == EACCES ? ErrorCode::kPermissionDenied : ErrorCode::kUnavailable,
                  Errno("bind " + options.path));
    ::close(fd);
    return status;
  }
  if (::chmod(options.path.c_str(), options.mode) != 0 ||
      (options.group &&
       ::chown(options.path.c_str(), static_cast<uid_t>(-1), *options.group) != 0)) {
    Status status(ErrorCode::kPermissionDenied, Errno("setting owner/mode of " + options.path));
    ::close(fd);
    ::unlink(options.path.c_str());
    return status;
  }
  if (::listen(fd, options.backlog) != 0) {
    Status status(ErrorCode::kUnavailable, Errno("listen " + options.path));
    ::close(fd);
    ::unlink(options.path.c_str());
    return status;
  }
  std::unique_ptr<UnixListener> listener(new UnixListener(options, fd));
  if (::pipe2(listener->wake_, O_CLOEXEC) != 0)
    return Status(ErrorCode::kUnavailable, Errno("pipe"));
  listener->spare_ = ::open("/dev/null", O_RDONLY | O_CLOEXEC);
  if (listener->spare_ < 0) return Status(ErrorCode::kUnavailable, Errno("open /dev/null"));
  return listener;
}

UnixListener::~UnixListener() {
  Stop();
  if (fd_ >= 0) ::close(fd_);
  for (int& end : wake_)
    if (end >= 0) ::close(end);
  if (spare_ >= 0) ::close(spare_);
}

void UnixListener::Start(grpc::Server* server, PeerRegistry* registry, const RolePolicy* policy) {
  thread_ = std::thread([this, server, registry, policy] { AcceptLoop(server, registry, policy); });
}

void UnixListener::Stop() {
  if (thread_.joinable()) {
    const char byte = 0;
    [[maybe_unused]] const ssize_t n = ::write(wake_[1], &byte, 1);
    thread_.join();
    ::unlink(options_.path.c_str());
  }
}

void UnixListener::AcceptLoop(grpc::Server* server, PeerRegistry* registry,
                              const RolePolicy* policy) {
  for (;;) {
    pollfd fds[2] = {{fd_, POLLIN, 0}, {wake_[0], POLLIN, 0}};
    if (::poll(fds, 2, -1) < 0) {
      if (errno == EINTR) continue;
      return;
    }
    if (fds[1].revents != 0) return;
    const int connection = ::accept4(fd_, nullptr, nullptr, SOCK_CLOEXEC | SOCK_NONBLOCK);
    if (connection < 0) {
      if (errno == EMFILE || errno == ENFILE) {
        // Out of descriptors: the waiting connection would keep poll awake
        // and this loop spinning. Shed it through the spare descriptor,
        // then wait a moment (or for Stop).
        if (spare_ >= 0) {
          ::close(spare_);
          const int shed = ::accept4(fd_, nullptr, nullptr, SOCK_CLOEXEC);
          if (shed >= 0) {
            ::close(shed);
            ++shed_;
          }
          spare_ = ::open("/dev/null", O_RDONLY | O_CLOEXEC);
        }
        pollfd wake = {wake_[0], POLLIN, 0};
        if (::poll(&wake, 1, kDescriptorBackoffMs) > 0) return;
      }
      continue;  // EAGAIN, ECONNABORTED: try the next one
    }
    ucred credentials{};
    socklen_t length = sizeof(credentials);
    struct stat socket_file {};
    if (::getsockopt(connection, SOL_SOCKET, SO_PEERCRED, &credentials, &length) != 0 ||
        ::fstat(connection, &socket_file) != 0) {
      ::close(connection);
      continue;
    }
    ForgetClosed();
    if (const std::string why = OverLimit(credentials.uid); !why.empty()) {
      ::close(connection);
      ++refused_;
      LogRefusal(credentials.uid, why);
      continue;
    }
    handed_[connection] = {socket_file.st_ino, credentials.uid};
    Caller caller;
    caller.uid = credentials.uid;
    caller.name = UserName(credentials.uid);
    caller.transport = "unix";
    caller.role = policy->RoleOfUid(credentials.uid);
    // gRPC names the connection after the descriptor it is given.
    registry->Add("fd:" + std::to_string(connection), std::move(caller));
    ++accepted_;
    grpc::AddInsecureChannelFromFd(server, connection);
  }
}

void UnixListener::ForgetClosed() {
  for (auto it = handed_.begin(); it != handed_.end();) {
    struct stat now {};
    const bool same =
        ::fstat(it->first, &now) == 0 && S_ISSOCK(now.st_mode) && now.st_ino == it->second.inode;
    it = same ? std::next(it) : handed_.erase(it);
  }
}

std::string UnixListener::OverLimit(uid_t uid) const {
  if (static_cast<int>(handed_.size()) >= options_.max_connections)
    return std::to_string(handed_.size()) + " connections are open (listen.max_connections " +
           std::to_string(options_.max_connections) + ")";
  int mine = 0;
  for (const auto& [fd, handed] : handed_) mine += handed.uid == uid ? 1 : 0;
  if (mine >= options_.max_connections_per_user)
    return "the user has " + std::to_string(mine) +
           " connections open (listen.max_connections_per_user " +
           std::to_string(options_.max_connections_per_user) + ")";
  return "";
}

void UnixListener::LogRefusal(uid_t uid, const std::string& why) {
  ++refused_unlogged_;
  const auto now = std::chrono::steady_clock::now();
  if (now - last_refusal_log_ < std::chrono::seconds(1)) return;
  spdlog::warn("refused {} connection(s) on {} since the last report; the last of {} (uid {}): {}",
               refused_unlogged_, options_.path, UserName(uid), uid, why);
  refused_unlogged_ = 0;
  last_refusal_log_ = now;
}

}  // namespace bsls::service
