#include "bsls/rpc/unix_acceptor.h"

#include <fcntl.h>
#include <poll.h>
#include <spdlog/spdlog.h>
#include <sys/stat.h>
#include <sys/un.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

#include "bsls/rpc/unix_socket.h"

namespace bsls::rpc {
namespace {

// How long the accept loop waits after shedding a connection for want of
// descriptors (EMFILE, ENFILE), before it accepts again.
constexpr int kDescriptorBackoffMs = 50;

std::string Errno(const std::string& what) { return what + ": " + std::strerror(errno); }

// The (device, inode) of the file at `path`, if there is one.
std::optional<std::pair<dev_t, ino_t>> FileId(const std::string& path) {
  struct stat st {};
  if (::lstat(path.c_str(), &st) != 0) return std::nullopt;
  return std::make_pair(st.st_dev, st.st_ino);
}

}  // namespace

UnixAcceptor::UnixAcceptor(UnixAcceptorOptions options, int fd)
    : options_(std::move(options)), fd_(fd) {}

std::unique_ptr<UnixAcceptor> UnixAcceptor::Create(const UnixAcceptorOptions& options,
                                                   UnixAcceptorError* error) {
  auto fail = [error](UnixAcceptorError::Kind kind, std::string message) {
    *error = {kind, std::move(message)};
    return std::unique_ptr<UnixAcceptor>();
  };
  sockaddr_un address{};
  address.sun_family = AF_UNIX;
  if (options.path.empty() || options.path.size() >= sizeof(address.sun_path))
    return fail(UnixAcceptorError::Kind::kInvalidPath,
                "socket path '" + options.path + "' is empty or longer than " +
                    std::to_string(sizeof(address.sun_path) - 1) + " bytes");
  std::memcpy(address.sun_path, options.path.c_str(), options.path.size() + 1);

  if (const std::string taken = ClaimUnixSocketPath(options.path); !taken.empty())
    return fail(UnixAcceptorError::Kind::kTaken, "socket path: " + taken);
  const int fd = ::socket(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC | SOCK_NONBLOCK, 0);
  if (fd < 0) return fail(UnixAcceptorError::Kind::kSystem, Errno("socket(AF_UNIX)"));
  std::unique_ptr<UnixAcceptor> acceptor(new UnixAcceptor(options, fd));
  // The file is created with the umask applied; permissions are set next,
  // before anyone is accepted.
  if (::bind(fd, reinterpret_cast<const sockaddr*>(&address), sizeof(address)) != 0)
    return fail(errno == EACCES ? UnixAcceptorError::Kind::kPermissionDenied
                                : UnixAcceptorError::Kind::kSystem,
                Errno("bind " + options.path));
  acceptor->socket_file_ = FileId(options.path);
  // From here on a failure removes the socket file bound above (while it is
  // that file), so that no stale file is left for the next start to find.
  const auto fail_bound = [&](UnixAcceptorError::Kind kind, std::string message) {
    if (acceptor->socket_file_ && FileId(options.path) == acceptor->socket_file_)
      ::unlink(options.path.c_str());
    return fail(kind, std::move(message));
  };
  if (::chmod(options.path.c_str(), options.mode) != 0 ||
      (options.group && ::chown(options.path.c_str(), static_cast<uid_t>(-1), *options.group) != 0))
    return fail_bound(UnixAcceptorError::Kind::kPermissionDenied,
                      Errno("setting owner/mode of " + options.path));
  if (::listen(fd, options.backlog) != 0)
    return fail_bound(UnixAcceptorError::Kind::kSystem, Errno("listen " + options.path));
  if (::pipe2(acceptor->wake_, O_CLOEXEC) != 0)
    return fail_bound(UnixAcceptorError::Kind::kSystem, Errno("pipe"));
  acceptor->spare_ = ::open("/dev/null", O_RDONLY | O_CLOEXEC);
  if (acceptor->spare_ < 0)
    return fail_bound(UnixAcceptorError::Kind::kSystem, Errno("open /dev/null"));
  return acceptor;
}

UnixAcceptor::~UnixAcceptor() {
  Stop();
  if (fd_ >= 0) ::close(fd_);
  for (int& end : wake_)
    if (end >= 0) ::close(end);
  if (spare_ >= 0) ::close(spare_);
}

void UnixAcceptor::Start(HandOver hand_over) {
  thread_ = std::thread([this, hand_over = std::move(hand_over)] { AcceptLoop(hand_over); });
}

void UnixAcceptor::Stop() {
  if (!thread_.joinable()) return;
  const char byte = 0;
  [[maybe_unused]] const ssize_t n = ::write(wake_[1], &byte, 1);
  thread_.join();
  // Only the file made here: another instance may have replaced a socket
  // it found stale.
  if (socket_file_ && FileId(options_.path) == socket_file_) ::unlink(options_.path.c_str());
}

void UnixAcceptor::AcceptLoop(const HandOver& hand_over) {
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
    ++accepted_;
    hand_over(connection, credentials);
  }
}

void UnixAcceptor::ForgetClosed() {
  for (auto it = handed_.begin(); it != handed_.end();) {
    struct stat now {};
    const bool same =
        ::fstat(it->first, &now) == 0 && S_ISSOCK(now.st_mode) && now.st_ino == it->second.inode;
    it = same ? std::next(it) : handed_.erase(it);
  }
}

std::string UnixAcceptor::OverLimit(uid_t uid) const {
  if (static_cast<int>(handed_.size()) >= options_.connections.max_connections)
    return std::to_string(handed_.size()) + " connections are open (listen.max_connections " +
           std::to_string(options_.connections.max_connections) + ")";
  int mine = 0;
  for (const auto& [fd, handed] : handed_) mine += handed.uid == uid ? 1 : 0;
  if (mine >= options_.connections.max_connections_per_user)
    return "the user has " + std::to_string(mine) +
           " connections open (listen.max_connections_per_user " +
           std::to_string(options_.connections.max_connections_per_user) + ")";
  return "";
}

void UnixAcceptor::LogRefusal(uid_t uid, const std::string& why) {
  ++refused_unlogged_;
  const auto now = std::chrono::steady_clock::now();
  if (now - last_refusal_log_ < std::chrono::seconds(1)) return;
  spdlog::warn("refused {} connection(s) on {} since the last report; the last of uid {}: {}",
               refused_unlogged_, options_.path, uid, why);
  refused_unlogged_ = 0;
  last_refusal_log_ = now;
}

}  // namespace bsls::rpc
