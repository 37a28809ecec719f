#include "server.h"

#include <spdlog/spdlog.h>
#include <sys/stat.h>

#include <filesystem>
#include <optional>
#include <stdexcept>
#include <thread>

#include "bsls/rpc/malformed_requests.h"
#include "bsls/rpc/server_limits.h"
#include "bsls/rpc/tls.h"
#include "bsls/rpc/unix_socket.h"

namespace bsls::processd {
namespace {

// The (device, inode) of the file at `path`, if there is one.
std::optional<std::pair<dev_t, ino_t>> FileId(const std::string& path) {
  struct stat st {};
  if (::lstat(path.c_str(), &st) != 0) return std::nullopt;
  return std::make_pair(st.st_dev, st.st_ino);
}

}  // namespace

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
  s->service_ = std::make_unique<processing::ProcessingService>(options);

  grpc::EnableDefaultHealthCheckService(true);
  grpc::ServerBuilder builder;
  builder.SetMaxReceiveMessageSize(config.listen.max_receive_message_bytes);
  builder.SetMaxSendMessageSize(config.listen.max_send_message_bytes);
  rpc::ApplyHttp2Limits(config.listen.http2, builder);
  rpc::ReportMalformedRequests(builder);
  // Handler threads: every worker and queue place, plus quick calls.
  grpc::ResourceQuota quota("bsls-processd");
  quota.SetMaxThreads(options.workers + options.queue + 16);
  builder.SetResourceQuota(quota);
  builder.RegisterService(s->service_.get());
  if (!config.listen.unix_socket.empty()) {
    if (const std::string taken = rpc::ClaimUnixSocketPath(config.listen.unix_socket);
        !taken.empty())
      throw std::runtime_error("listen.unix_socket: " + taken);
    builder.AddListeningPort("unix:" + config.listen.unix_socket,
                             grpc::InsecureServerCredentials());
  }
  if (!config.listen.tcp.empty()) {
    rpc::TlsFiles tls{config.listen.tls_client_ca, config.listen.tls_certificate,
                      config.listen.tls_key,       "listen.tls_client_ca",
                      "listen.tls_certificate",    "listen.tls_key"};
    builder.AddListeningPort(config.listen.tcp,
                             config.listen.plaintext_loopback
                                 ? grpc::InsecureServerCredentials()
                                 : rpc::MutualTlsServerCredentials(tls),
                             &s->tcp_port_);
  }
  s->server_ = builder.BuildAndStart();
  if (s->server_ && !config.listen.unix_socket.empty())
    s->socket_file_ = FileId(config.listen.unix_socket);
  if (!s->server_ || (!config.listen.tcp.empty() && s->tcp_port_ == 0))
    throw std::runtime_error(
        "the gRPC server could not start" +
        (config.listen.tcp.empty() ? std::string() : " on TCP " + config.listen.tcp) +
        (config.listen.unix_socket.empty() ? std::string()
                                           : " (socket " + config.listen.unix_socket + ")"));
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
  // Only the file this server made: another instance may have replaced a
  // socket it found stale.
  if (socket_file_ && FileId(config_.listen.unix_socket) == socket_file_) {
    std::error_code ec;
    std::filesystem::remove(config_.listen.unix_socket, ec);
  }
}

}  // namespace bsls::processd
