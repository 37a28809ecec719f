#include "daemon.h"

#include <grp.h>
#include <grpcpp/server_builder.h>
#include <spdlog/spdlog.h>

#include <tuple>

#include "bsls/calibration/calibration_header.h"
#include "bsls/rpc/malformed_requests.h"
#include "bsls/rpc/server_limits.h"
#include "bsls/rpc/tls.h"
#include "bsls/service/contract_messages.h"

#ifndef BSLS_VERSION
#define BSLS_VERSION "unknown"
#endif

namespace bsls::bslsd {

namespace {

// The capture store of `config`, opened; its recovery report logged.
// Recovery reports damaged acknowledged captures, never drops them.
Result<std::unique_ptr<store::CaptureStore>> OpenStore(const Config& config) {
  Result<std::unique_ptr<store::CaptureStore>> opened = store::CaptureStore::Open(config.store);
  if (!opened.ok())
    return Status(opened.status().code(), "capture store: " + opened.status().message());
  const store::RecoveryReport& recovery = (*opened)->recovery_report();
  spdlog::info("capture store {}: {} captures checked, {} damaged, {} leftovers removed",
               config.store.root, recovery.captures_checked, recovery.problems.size(),
               recovery.temp_files_removed + recovery.orphan_files_removed);
  for (const store::CaptureProblem& problem : recovery.problems)
    spdlog::error("capture {} is damaged: {}", problem.id, problem.status.message());
  return opened;
}

// The device's callbacks: `tick` for the watchdog, and device lost, found
// and camera changed logged and published on `events`.
service::DeviceCallbacks DeviceEvents(service::EventHub* events, std::function<void()> tick) {
  service::DeviceCallbacks callbacks;
  callbacks.tick = std::move(tick);
  callbacks.lost = [events](const std::string& reason) {
    spdlog::error("framestore lost: {}", reason);
    v1::Event event;
    event.mutable_device_lost()->set_reason(reason);
    events->Publish(std::move(event));
  };
  callbacks.found = [events](const std::string& device) {
    spdlog::info("framestore found again: {}", device);
    v1::Event event;
    event.mutable_device_found()->set_device(device);
    events->Publish(std::move(event));
  };
  callbacks.camera_changed = [events](framestore::Camera camera, int gain) {
    v1::Event event;
    event.mutable_camera_changed()->set_camera(service::ToProto(camera));
    event.mutable_camera_changed()->set_gain(gain);
    events->Publish(std::move(event));
  };
  return callbacks;
}

// The processing queue's options from config.processing, with the text of
// each calibration file named there (checked to be of its side);
// kInvalidArgument naming the key when one is not.
Status ReadProcessingOptions(const Config& config, service::ProcessingQueueOptions* processing) {
  const ProcessingConfig& p = config.processing;
  processing->client.target = p.server;
  processing->client.tls = {p.tls_ca,
                            p.tls_certificate,
                            p.tls_key,
                            "processing.tls_ca",
                            "processing.tls_certificate",
                            "processing.tls_key"};
  processing->client.timeout = std::chrono::milliseconds(p.timeout_ms);
  processing->retry_initial = std::chrono::milliseconds(p.retry_initial_ms);
  processing->retry_max = std::chrono::milliseconds(p.retry_max_ms);
  processing->daemon_version = BSLS_VERSION;
  for (const auto& [file, key, side, out] :
       {std::tuple{p.calibration_left, "processing.calibration_left", pattern::Side::kLeft,
                   &processing->left_calibration},
        std::tuple{p.calibration_right, "processing.calibration_right", pattern::Side::kRight,
                   &processing->right_calibration}}) {
    if (file.empty()) continue;
    // The head only (format, version, side): the processing service checks
    // the whole calibration when it is used.
    try {
      std::string text = calibration::ReadCalibrationText(file);
      const calibration::CalibrationHeader header =
          calibration::ReadCalibrationHeader(calibration::ParseCalibrationYaml(text, file), file);
      if (header.side != side)
        return Status(ErrorCode::kInvalidArgument,
                      std::string(key) + " " + file + ": is a calibration of the other side");
      *out = std::move(text);
    } catch (const calibration::CalibrationFileError& e) {
      return Status(ErrorCode::kInvalidArgument, std::string(key) + ": " + e.what());
    }
  }
  return Status();
}

// Starts the processing queue; kInvalidArgument when its TLS files or its
// server address are unusable.
Status StartProcessing(service::ProcessingQueue& queue) {
  try {
    queue.Start();
  } catch (const rpc::TlsFileError& e) {
    return Status(ErrorCode::kInvalidArgument, e.what());
  } catch (const std::invalid_argument& e) {
    return Status(ErrorCode::kInvalidArgument, std::string("processing.server: ") + e.what());
  }
  return Status();
}

// Sets `builder` up to serve `service` with config.listen's limits and, when
// it names a TCP address, binds it into *tcp with mutual TLS (its connections
// within listen.max_tcp_connections*); kInvalidArgument when the TLS files
// are unusable, kUnavailable when the address cannot be bound.
Status ConfigureServer(const Config& config, grpc::Service* service, rpc::TcpListener* tcp,
                       grpc::ServerBuilder& builder) {
  builder.SetMaxReceiveMessageSize(config.listen.max_receive_message_bytes);
  builder.SetMaxSendMessageSize(config.listen.max_send_message_bytes);
  rpc::ApplyHttp2Limits(config.listen.http2, builder);
  rpc::ReportMalformedRequests(builder);
  grpc::ResourceQuota quota("bslsd");
  quota.SetMaxThreads(64);
  builder.SetResourceQuota(quota);
  builder.RegisterService(service);
  if (!config.listen.tcp.empty()) {
    // Mutual TLS only, ended by the HTTP/2 guard: a client without a
    // certificate signed by the CA fails the handshake and never reaches gRPC.
    rpc::TcpListenerOptions options;
    options.acceptor.address = config.listen.tcp;
    options.acceptor.connections = config.listen.connections;
    options.guard = config.listen.guard;
    options.tls = rpc::ListenTlsFiles(config.listen.tls_client_ca, config.listen.tls_certificate,
                                      config.listen.tls_key);
    options.handshake_timeout_ms = config.listen.http2.handshake_timeout_ms;
    try {
      *tcp = rpc::ListenTcp(options);
    } catch (const rpc::TlsFileError& e) {
      return Status(ErrorCode::kInvalidArgument, e.what());
    } catch (const std::runtime_error& e) {
      return Status(ErrorCode::kUnavailable, e.what());
    }
  }
  return Status();
}

}  // namespace

Result<std::unique_ptr<service::UnixListener>> OpenUnixListener(const Config& config) {
  if (config.listen.unix_socket.empty()) return std::unique_ptr<service::UnixListener>();
  service::UnixListenerOptions options;
  options.path = config.listen.unix_socket;
  options.mode = static_cast<mode_t>(config.listen.socket_mode);
  options.connections = config.listen.connections;
  options.http2_guard = config.listen.guard;
  options.handshake_timeout_ms = config.listen.http2.handshake_timeout_ms;
  const std::string& group = config.listen.socket_group;
  if (!group.empty()) {
    if (group.find_first_not_of("0123456789") == std::string::npos && group.size() <= 9) {
      options.group = static_cast<gid_t>(std::stoul(group));  // a gid without a name
    } else if (struct group* entry = ::getgrnam(group.c_str()); entry != nullptr) {
      options.group = entry->gr_gid;
    } else {
      return Status(ErrorCode::kInvalidArgument,
                    "listen.socket_group: group '" + group + "' does not exist");
    }
  }
  Result<std::unique_ptr<service::UnixListener>> listener = service::UnixListener::Create(options);
  if (!listener.ok())
    return Status(listener.status().code(), "listen.unix_socket: " + listener.status().message());
  return listener;
}

Result<std::unique_ptr<Daemon>> Daemon::Start(const Config& config, PrivilegedDevices privileged,
                                              std::function<void()> tick,
                                              std::unique_ptr<service::UnixListener> listener) {
  std::unique_ptr<Daemon> d(new Daemon);
  d->config_ = config;
  Result<service::RolePolicy> policy = ResolveRoles(config.roles);
  if (!policy.ok()) return policy.status();
  d->policy_ = std::move(policy).value();

  Result<std::unique_ptr<store::CaptureStore>> opened = OpenStore(config);
  if (!opened.ok()) return opened.status();
  d->store_ = std::move(opened).value();

  Result<std::unique_ptr<slides::SlideController>> slides = OpenSlides(config, &d->events_);
  if (!slides.ok()) return slides.status();
  d->slides_ = std::move(slides).value();
  Result<std::unique_ptr<framestore::Framestore>> framestore =
      OpenFramestore(config, std::move(privileged), d->slides_.get());
  if (!framestore.ok()) return framestore.status();
  spdlog::info("framestore: {}", (*framestore)->capabilities().device);
  d->device_ = std::make_unique<service::CaptureDevice>(std::move(framestore).value(),
                                                        DeviceEvents(&d->events_, std::move(tick)));

  // The processing queue: captures of earlier runs first, then every new grab.
  service::ProcessingQueueOptions processing;
  if (Status read = ReadProcessingOptions(config, &processing); !read.ok()) return read;
  d->processing_ =
      std::make_unique<service::ProcessingQueue>(d->store_.get(), &d->events_, processing);
  if (Status started = StartProcessing(*d->processing_); !started.ok()) return started;
  if (d->processing_->enabled())
    spdlog::info("processing: every grab goes to {}", config.processing.server);

  d->service_ = std::make_unique<service::CaptureService>(
      d->device_.get(), d->store_.get(), d->slides_.get(), &d->events_, &d->peers_, &d->policy_,
      config.limits, BSLS_VERSION, d->processing_.get());

  grpc::ServerBuilder builder;
  if (Status configured = ConfigureServer(config, d->service_.get(), &d->tcp_, builder);
      !configured.ok())
    return configured;
  d->server_ = builder.BuildAndStart();
  if (d->server_ && d->tcp_.acceptor) {
    d->tcp_port_ = d->tcp_.acceptor->port();
    service::StartTcpListener(d->tcp_, d->server_.get(), &d->peers_, &d->policy_);
  }
  if (!d->server_ || (!config.listen.tcp.empty() && d->tcp_port_ == 0))
    return Status(ErrorCode::kUnavailable,
                  "the gRPC server could not start" +
                      (config.listen.tcp.empty() ? std::string() : " on TCP " + config.listen.tcp));
  if (!listener) {
    Result<std::unique_ptr<service::UnixListener>> socket = OpenUnixListener(config);
    if (!socket.ok()) return socket.status();
    listener = std::move(socket).value();
  }
  if (listener) {
    d->listener_ = std::move(listener);
    d->listener_->Start(d->server_.get(), &d->peers_, &d->policy_);
  }
  return d;
}

Daemon::~Daemon() { Drain(); }

void Daemon::Drain() {
  if (drained_) return;
  drained_ = true;
  if (service_) service_->BeginDrain();
  if (listener_) listener_->Stop();
  tcp_.Stop();
  // The call under way is cancelled; its capture stays pending for the next start.
  if (processing_) processing_->Stop();
  events_.Close();
  if (server_) {
    // Calls under way (a grab being stored) finish; then the rest are cancelled.
    server_->Shutdown(std::chrono::system_clock::now() + config_.drain_timeout);
    server_->Wait();
  }
}

void Daemon::ApplyRetention() {
  if (!config_.store.retention.max_age && !config_.store.retention.max_total_bytes) return;
  Result<store::RetentionReport> report = store_->ApplyRetention(std::chrono::system_clock::now());
  if (!report.ok())
    spdlog::error("retention: {}", report.status().message());
  else if (!report->deleted.empty())
    spdlog::info("retention deleted {} captures ({} bytes)", report->deleted.size(),
                 report->bytes_freed);
}

}  // namespace bsls::bslsd
