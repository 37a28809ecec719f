#include "bsls/rpc/unix_acceptor.h"

#include <sys/stat.h>
#include <sys/un.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <utility>

#include "acceptor.h"
#include "bsls/rpc/unix_socket.h"

namespace bsls::rpc {
namespace {

std::string Errno(const std::string& what) { return what + ": " + std::strerror(errno); }

// The (device, inode) of the file at `path`, if there is one.
std::optional<std::pair<dev_t, ino_t>> FileId(const std::string& path) {
  struct stat st {};
  if (::lstat(path.c_str(), &st) != 0) return std::nullopt;
  return std::make_pair(st.st_dev, st.st_ino);
}

// A Unix-socket connection's peer: its credentials, named by uid.
std::optional<Peer> PeerOfUnixConnection(int fd) {
  Peer peer;
  socklen_t length = sizeof(peer.credentials);
  if (::getsockopt(fd, SOL_SOCKET, SO_PEERCRED, &peer.credentials, &length) != 0)
    return std::nullopt;
  peer.name = "uid " + std::to_string(peer.credentials.uid);
  return peer;
}

}  // namespace

UnixAcceptor::UnixAcceptor(UnixAcceptorOptions options, std::unique_ptr<Http2Guard> guard,
                           std::unique_ptr<Acceptor> core,
                           std::optional<std::pair<dev_t, ino_t>> socket_file)
    : options_(std::move(options)),
      guard_(std::move(guard)),
      core_(std::move(core)),
      socket_file_(socket_file) {}

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
  int fd = ::socket(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC | SOCK_NONBLOCK, 0);
  if (fd < 0) return fail(UnixAcceptorError::Kind::kSystem, Errno("socket(AF_UNIX)"));
  // Closed on a failure until the accept loop owns it.
  const std::unique_ptr<int, void (*)(int*)> owned(&fd, [](int* open) {
    if (*open >= 0) ::close(*open);
  });
  // The file is created with the umask applied; permissions are set next,
  // before anyone is accepted.
  if (::bind(fd, reinterpret_cast<const sockaddr*>(&address), sizeof(address)) != 0)
    return fail(errno == EACCES ? UnixAcceptorError::Kind::kPermissionDenied
                                : UnixAcceptorError::Kind::kSystem,
                Errno("bind " + options.path));
  const std::optional<std::pair<dev_t, ino_t>> socket_file = FileId(options.path);
  // From here on a failure removes the socket file bound above (while it is
  // that file), so that no stale file is left for the next start to find.
  const auto fail_bound = [&](UnixAcceptorError::Kind kind, std::string message) {
    if (socket_file && FileId(options.path) == socket_file) ::unlink(options.path.c_str());
    return fail(kind, std::move(message));
  };
  if (::chmod(options.path.c_str(), options.mode) != 0 ||
      (options.group && ::chown(options.path.c_str(), static_cast<uid_t>(-1), *options.group) != 0))
    return fail_bound(UnixAcceptorError::Kind::kPermissionDenied,
                      Errno("setting owner/mode of " + options.path));
  if (::listen(fd, options.backlog) != 0)
    return fail_bound(UnixAcceptorError::Kind::kSystem, Errno("listen " + options.path));
  AcceptLimits limits{options.connections.max_connections, "listen.max_connections",
                      options.connections.max_connections_per_user,
                      "listen.max_connections_per_user"};
  std::string why;
  std::unique_ptr<Acceptor> core = Acceptor::Create({std::exchange(fd, -1)}, "unix:" + options.path,
                                                    std::move(limits), PeerOfUnixConnection, &why);
  if (!core) return fail_bound(UnixAcceptorError::Kind::kSystem, options.path + ": " + why);
  std::unique_ptr<Http2Guard> guard;
  if (options.http2_guard) {
    guard = Http2Guard::Create(*options.http2_guard, &why, nullptr, options.handshake_timeout_ms);
    if (!guard) return fail_bound(UnixAcceptorError::Kind::kSystem, options.path + ": " + why);
  }
  return std::unique_ptr<UnixAcceptor>(
      new UnixAcceptor(options, std::move(guard), std::move(core), socket_file));
}

UnixAcceptor::~UnixAcceptor() { Stop(); }

void UnixAcceptor::Start(HandOver hand_over) {
  if (guard_) guard_->Start();
  core_->Start(
      [hand_over = std::move(hand_over), guard = guard_.get()](int client, int, const Peer& peer) {
        if (!guard) {
          hand_over(client, peer.credentials);
          return true;
        }
        std::string ignored;  // the only reason: no descriptors for the socket pair
        return guard->Guard(
            client, [&](int fd, const std::string&) { hand_over(fd, peer.credentials); }, &ignored);
      });
}

void UnixAcceptor::Stop() {
  if (!core_->Stop()) return;
  // Only the file made here: another instance may have replaced a socket
  // it found stale.
  if (socket_file_ && FileId(options_.path) == socket_file_) ::unlink(options_.path.c_str());
}

std::uint64_t UnixAcceptor::accepted() const { return core_->accepted(); }

std::uint64_t UnixAcceptor::shed() const { return core_->shed(); }

std::uint64_t UnixAcceptor::refused() const { return core_->refused(); }

}  // namespace bsls::rpc
