#include "bsls/service/unix_listener.h"

#include <grpcpp/server.h>
#include <grpcpp/server_posix.h>
#include <pwd.h>
#include <sys/socket.h>

#include <vector>

namespace bsls::service {

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

std::string UserName(uid_t uid) {
  std::vector<char> buffer(16384);
  passwd entry{};
  passwd* found = nullptr;
  if (::getpwuid_r(uid, &entry, buffer.data(), buffer.size(), &found) == 0 && found != nullptr)
    return found->pw_name;
  return "uid" + std::to_string(uid);
}

}  // namespace

UnixListener::UnixListener(std::unique_ptr<rpc::UnixAcceptor> acceptor)
    : acceptor_(std::move(acceptor)) {}

Result<std::unique_ptr<UnixListener>> UnixListener::Create(const UnixListenerOptions& options) {
  rpc::UnixAcceptorOptions socket;
  socket.path = options.path;
  socket.mode = options.mode;
  socket.group = options.group;
  socket.backlog = options.backlog;
  socket.connections = options.connections;
  socket.http2_guard = options.http2_guard;
  socket.handshake_timeout_ms = options.handshake_timeout_ms;
  rpc::UnixAcceptorError error;
  std::unique_ptr<rpc::UnixAcceptor> acceptor = rpc::UnixAcceptor::Create(socket, &error);
  if (!acceptor) {
    switch (error.kind) {
      case rpc::UnixAcceptorError::Kind::kInvalidPath:
        return Status(ErrorCode::kInvalidArgument, error.message);
      case rpc::UnixAcceptorError::Kind::kTaken:
        return Status(ErrorCode::kAlreadyExists, error.message);
      case rpc::UnixAcceptorError::Kind::kPermissionDenied:
        return Status(ErrorCode::kPermissionDenied, error.message);
      case rpc::UnixAcceptorError::Kind::kSystem:
        break;
    }
    return Status(ErrorCode::kUnavailable, error.message);
  }
  return std::unique_ptr<UnixListener>(new UnixListener(std::move(acceptor)));
}

UnixListener::~UnixListener() { Stop(); }

void UnixListener::Start(grpc::Server* server, PeerRegistry* registry, const RolePolicy* policy) {
  acceptor_->Start([server, registry, policy](int fd, const ucred& peer) {
    Caller caller;
    caller.uid = peer.uid;
    caller.name = UserName(peer.uid);
    caller.transport = "unix";
    caller.role = policy->RoleOfUid(peer.uid);
    // gRPC names the connection after the descriptor it is given.
    registry->Add("fd:" + std::to_string(fd), std::move(caller));
    grpc::AddInsecureChannelFromFd(server, fd);
  });
}

void UnixListener::Stop() { acceptor_->Stop(); }

void StartTcpListener(rpc::TcpListener& tcp, grpc::Server* server, PeerRegistry* registry,
                      const RolePolicy* policy) {
  tcp.Start([server, registry, policy](int fd, const std::string& common_name) {
    Caller caller;
    caller.name = common_name;
    caller.transport = "tcp";
    caller.role = policy->RoleOfCertificate(common_name);
    registry->Add("fd:" + std::to_string(fd), std::move(caller));
    grpc::AddInsecureChannelFromFd(server, fd);
  });
}

}  // namespace bsls::service
