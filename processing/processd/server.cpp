#include "server.h"

#include <grpcpp/server_posix.h>
#include <spdlog/spdlog.h>

#include <stdexcept>
#include <thread>

#include "bsls/rpc/malformed_requests.h"
#include "bsls/rpc/server_limits.h"
#include "bsls/rpc/tls.h"

namespace bsls::processd {

std::unique_ptr<Server> Server::Start(const Config& config, const std::string& software_version) {
  Validate(config);
  std::unique_ptr<Server> s(new Server);
  s->config_ = config;

  processing::ProcessingServiceOptions options;
  options.workers = Workers(config);
  options.queue = Queue(config);
  options.calibration_cache_entries = static_cast<std::size_t>(config.calibration_cache_entries);
  options.replica = config.replica;
  options.software_version = software_version;
  if (!config.scratch_dir.empty()) options.scratch_dir = config.scratch_dir;
  options.max_upload_bytes = config.max_upload_bytes;
  options.max_frame_pixels = config.max_frame_pixels;
  s->service_ = std::make_unique<processing::ProcessingService>(options);

  grpc::EnableDefaultHealthCheckService(true);
  grpc::ServerBuilder builder;
  builder.SetMaxReceiveMessageSize(config.listen.max_receive_message_bytes);
  builder.SetMaxSendMessageSize(config.listen.max_send_message_bytes);
  rpc::ApplyHttp2Limits(config.listen.http2, builder);
  rpc::ReportMalformedRequests(builder);
  // Synchronous handler threads: Calibrate holds one for its upload and
  // while its work runs (at most every worker and queue place), plus the
  // quick calls. The other work calls are on the callback API and hold none.
  grpc::ResourceQuota quota("bsls-processd");
  quota.SetMaxThreads(options.workers + options.queue + 16);
  builder.SetResourceQuota(quota);
  builder.RegisterService(s->service_.get());
  if (!config.listen.unix_socket.empty()) {
    rpc::UnixAcceptorOptions socket;
    socket.path = config.listen.unix_socket;
    socket.mode = 0660;
    socket.connections = config.listen.connections;
    socket.http2_guard = config.listen.guard;  // new streams, resets, pings at a bounded rate
    socket.handshake_timeout_ms = config.listen.http2.handshake_timeout_ms;
    rpc::UnixAcceptorError error;
    s->acceptor_ = rpc::UnixAcceptor::Create(socket, &error);
    if (!s->acceptor_) throw std::runtime_error("listen.unix_socket: " + error.message);
  }
  if (!config.listen.tcp.empty()) {
    rpc::TcpListenerOptions tcp;
    tcp.acceptor.address = config.listen.tcp;
    tcp.acceptor.connections = config.listen.connections;
    // Plain TCP: a name that also resolves to a network address is refused.
    tcp.acceptor.loopback_only = config.listen.plaintext_loopback;
    tcp.guard = config.listen.guard;  // new streams, resets, pings at a bounded rate
    if (!config.listen.plaintext_loopback)
      tcp.tls = rpc::ListenTlsFiles(config.listen.tls_client_ca, config.listen.tls_certificate,
                                    config.listen.tls_key);
    tcp.handshake_timeout_ms = config.listen.http2.handshake_timeout_ms;
    s->tcp_ = rpc::ListenTcp(tcp);
    s->tcp_port_ = s->tcp_.acceptor->port();
  }
  s->server_ = builder.BuildAndStart();
  if (!s->server_ || (!config.listen.tcp.empty() && s->tcp_port_ == 0))
    throw std::runtime_error(
        "the gRPC server could not start" +
        (config.listen.tcp.empty() ? std::string() : " on TCP " + config.listen.tcp) +
        (config.listen.unix_socket.empty() ? std::string()
                                           : " (socket " + config.listen.unix_socket + ")"));
  grpc::Server* server = s->server_.get();
  if (s->tcp_.acceptor)
    s->tcp_.Start(
        [server](int fd, const std::string&) { grpc::AddInsecureChannelFromFd(server, fd); });
  if (s->acceptor_) {
    s->acceptor_->Start(
        [server](int fd, const ucred&) { grpc::AddInsecureChannelFromFd(server, fd); });
  }
  spdlog::info(
      "serving: {} workers, {} queue places{}{}", options.workers, options.queue,
      config.listen.unix_socket.empty() ? "" : ", unix:" + config.listen.unix_socket,
      config.listen.tcp.empty()
          ? ""
          : ", tcp port " + std::to_string(s->tcp_port_) +
                (config.listen.plaintext_loopback ? " (plain, loopback)" : " (mutual TLS)"));
  return s;
}

Server::~Server() { Drain(); }

void Server::Drain() {
  if (drained_) return;
  drained_ = true;
  if (service_) service_->BeginDrain();
  // No new connections; the socket file goes if it still is the one made here.
  if (acceptor_) acceptor_->Stop();
  tcp_.Stop();
  if (server_) {
    // Work under way stops at its next stage; wait for that (at most the
    // drain timeout), then shut down at once: gRPC's own deadline would also
    // wait for idle client connections (a daemon's channel) to go away.
    const auto until =
        std::chrono::steady_clock::now() + std::chrono::milliseconds(config_.drain_timeout_ms);
    while (std::chrono::steady_clock::now() < until) {
      const processing::WorkPoolStats s = service_->Stats();
      if (s.busy == 0 && s.waiting == 0) break;
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
    server_->Shutdown(std::chrono::system_clock::now() + std::chrono::milliseconds(100));
    server_->Wait();
  }
}

}  // namespace bsls::processd
