// bslsd: the BSLS capture daemon (issue 4). Owns the framestore and the slide
// controller, keeps every grab durably, and serves proto/bsls/v1/capture.proto
// on a Unix socket (roles from SO_PEERCRED) and, when configured, on TCP with
// mutual TLS.
//
// Start-up order matters for least privilege: the configuration is read, the
// devices that need CAP_SYS_RAWIO are opened while the process has a single
// thread, every capability is dropped (bslsd refuses to go on otherwise), and
// only then are threads started and network input parsed.
//
// Exit codes: 0 after a clean SIGTERM/SIGINT, 1 for runtime failures,
// 78 (EX_CONFIG) for what a restart cannot fix: a bad configuration, kernel
// lockdown forbidding port I/O, capabilities that cannot be dropped. The
// systemd unit lists 78 in RestartPreventExitStatus=, so a misconfigured
// daemon fails once with its cause instead of restart-looping.
#include <grp.h>
#include <signal.h>
#include <systemd/sd-daemon.h>

#include <CLI/CLI.hpp>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <fstream>
#include <grpcpp/grpcpp.h>
#include <grpcpp/security/server_credentials.h>
#include <memory>
#include <spdlog/spdlog.h>
#include <sstream>

#include "backends.h"
#include "bsls/service/capture_device.h"
#include "bsls/service/capture_service.h"
#include "bsls/service/event_hub.h"
#include "bsls/service/unix_listener.h"
#include "config.h"
#include "privileges.h"

#ifndef BSLS_VERSION
#define BSLS_VERSION "unknown"
#endif

namespace {

using namespace bsls;

constexpr int kExitRuntime = 1;
constexpr int kExitConfig = 78;  // EX_CONFIG: a restart will not help

// The watchdog: fed from the capture loop, at most every half interval.
class Watchdog {
 public:
  Watchdog() {
    std::uint64_t usec = 0;
    if (sd_watchdog_enabled(0, &usec) > 0) interval_ = std::chrono::microseconds(usec / 2);
  }
  void Feed() {
    if (interval_.count() == 0) return;
    const auto now = std::chrono::steady_clock::now().time_since_epoch().count();
    const auto last = last_.load();
    if (now - last < std::chrono::duration_cast<std::chrono::steady_clock::duration>(interval_).count())
      return;
    last_ = now;
    sd_notify(0, "WATCHDOG=1");
  }

 private:
  std::chrono::microseconds interval_{0};
  std::atomic<std::chrono::steady_clock::rep> last_{0};
};

std::string ReadFile(const std::string& path, bool* ok) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream buffer;
  buffer << in.rdbuf();
  *ok = static_cast<bool>(in) || in.eof();
  return buffer.str();
}

int Run(const bslsd::Config& config) {
  spdlog::set_level(spdlog::level::from_str(config.log_level));
  framestore::Result<service::RolePolicy> policy = bslsd::ResolveRoles(config.roles);
  if (!policy.ok()) {
    spdlog::critical("{}", policy.status().message());
    return kExitConfig;
  }

  // 1. Devices that need a privilege, while single-threaded.
  framestore::Result<bslsd::PrivilegedDevices> privileged = bslsd::OpenPrivileged(config);
  if (!privileged.ok()) {
    spdlog::critical("{}", privileged.status().message());
    return privileged.status().code() == framestore::ErrorCode::kPermissionDenied ? kExitConfig
                                                                                : kExitRuntime;
  }
  // 2. No privilege from here on.
  if (framestore::Status dropped = bslsd::DropAllCapabilities(); !dropped.ok()) {
    spdlog::critical("{}", dropped.message());
    return kExitConfig;
  }

  // Signals are taken by sigwait below; every thread started from here inherits the mask.
  sigset_t signals;
  sigemptyset(&signals);
  sigaddset(&signals, SIGTERM);
  sigaddset(&signals, SIGINT);
  sigaddset(&signals, SIGHUP);
  pthread_sigmask(SIG_BLOCK, &signals, nullptr);

  // 3. The store: recovery reports damaged acknowledged captures, never drops them.
  framestore::Result<std::unique_ptr<store::CaptureStore>> opened =
      store::CaptureStore::Open(config.store);
  if (!opened.ok()) {
    spdlog::critical("capture store: {}", opened.status().ToString());
    return kExitRuntime;
  }
  std::unique_ptr<store::CaptureStore> captures = std::move(opened).value();
  const store::RecoveryReport& recovery = captures->recovery_report();
  spdlog::info("capture store {}: {} captures checked, {} damaged, {} leftovers removed",
               config.store.root, recovery.captures_checked, recovery.problems.size(),
               recovery.temp_files_removed + recovery.orphan_files_removed);
  for (const store::CaptureProblem& problem : recovery.problems)
    spdlog::error("capture {} is damaged: {}", problem.id, problem.status.message());

  // 4. Slides and framestore.
  service::EventHub events;
  framestore::Result<std::unique_ptr<slides::SlideController>> slide_controller =
      bslsd::OpenSlides(config, &events);
  if (!slide_controller.ok()) {
    spdlog::critical("{}", slide_controller.status().message());
    return kExitRuntime;
  }
  std::unique_ptr<slides::SlideController> slides = std::move(slide_controller).value();
  framestore::Result<std::unique_ptr<framestore::Framestore>> framestore_opened =
      bslsd::OpenFramestore(config, std::move(privileged).value(), slides.get());
  if (!framestore_opened.ok()) {
    spdlog::critical("{}", framestore_opened.status().message());
    return framestore_opened.status().code() == framestore::ErrorCode::kInvalidArgument
               ? kExitConfig
               : kExitRuntime;
  }
  spdlog::info("framestore: {}", (*framestore_opened)->capabilities().device);

  Watchdog watchdog;
  service::DeviceCallbacks callbacks;
  callbacks.tick = [&watchdog] { watchdog.Feed(); };
  callbacks.lost = [&events](const std::string& reason) {
    spdlog::error("framestore lost: {}", reason);
    v1::Event event;
    event.mutable_device_lost()->set_reason(reason);
    events.Publish(std::move(event));
  };
  callbacks.found = [&events](const std::string& device) {
    spdlog::info("framestore found again: {}", device);
    v1::Event event;
    event.mutable_device_found()->set_device(device);
    events.Publish(std::move(event));
  };
  callbacks.camera_changed = [&events](framestore::Camera camera, int gain) {
    v1::Event event;
    event.mutable_camera_changed()->set_camera(
        static_cast<v1::Camera>(static_cast<int>(camera) + 1));
    event.mutable_camera_changed()->set_gain(gain);
    events.Publish(std::move(event));
  };
  service::CaptureDevice device(std::move(framestore_opened).value(), callbacks);

  // 5. The service.
  service::PeerRegistry peers;
  service::CaptureService service(&device, captures.get(), slides.get(), &events, &peers,
                                  &*policy, config.limits, BSLS_VERSION);
  grpc::ServerBuilder builder;
  builder.SetMaxReceiveMessageSize(config.listen.max_receive_message_bytes);
  builder.SetMaxSendMessageSize(config.listen.max_send_message_bytes);
  grpc::ResourceQuota quota("bslsd");
  quota.SetMaxThreads(64);
  builder.SetResourceQuota(quota);
  builder.RegisterService(&service);
  int tcp_port = 0;
  if (!config.listen.tcp.empty()) {
    bool ok_cert = false, ok_key = false, ok_ca = false;
    grpc::SslServerCredentialsOptions tls(GRPC_SSL_REQUEST_AND_REQUIRE_CLIENT_CERTIFICATE_AND_VERIFY);
    tls.pem_root_certs = ReadFile(config.listen.tls_client_ca, &ok_ca);
    tls.pem_key_cert_pairs.push_back(
        {ReadFile(config.listen.tls_key, &ok_key), ReadFile(config.listen.tls_certificate, &ok_cert)});
    if (!ok_cert || !ok_key || !ok_ca) {
      spdlog::critical("listen.tcp: cannot read the TLS files {}, {}, {}",
                       config.listen.tls_certificate, config.listen.tls_key,
                       config.listen.tls_client_ca);
      return kExitConfig;
    }
    builder.AddListeningPort(config.listen.tcp, grpc::SslServerCredentials(tls), &tcp_port);
  }
  std::unique_ptr<grpc::Server> server = builder.BuildAndStart();
  if (!server || (!config.listen.tcp.empty() && tcp_port == 0)) {
    spdlog::critical("the gRPC server could not start (TCP {})", config.listen.tcp);
    return kExitRuntime;
  }
  std::unique_ptr<service::UnixListener> listener;
  if (!config.listen.unix_socket.empty()) {
    service::UnixListenerOptions options;
    options.path = config.listen.unix_socket;
    options.mode = static_cast<mode_t>(config.listen.socket_mode);
    if (!config.listen.socket_group.empty()) {
      group* entry = ::getgrnam(config.listen.socket_group.c_str());
      if (entry == nullptr) {
        spdlog::critical("listen.socket_group: group '{}' does not exist",
                         config.listen.socket_group);
        return kExitConfig;
      }
      options.group = entry->gr_gid;
    }
    framestore::Result<std::unique_ptr<service::UnixListener>> created =
        service::UnixListener::Create(options);
    if (!created.ok()) {
      spdlog::critical("{}", created.status().message());
      return kExitRuntime;
    }
    listener = std::move(created).value();
    listener->Start(server.get(), &peers, &*policy);
  }
  spdlog::info("bslsd {} serving on {}{}", BSLS_VERSION, config.listen.unix_socket,
               tcp_port ? " and TCP port " + std::to_string(tcp_port) + " (mutual TLS)" : "");
  sd_notify(0, "READY=1\nSTATUS=serving");

  // 6. Until SIGTERM/SIGINT; retention runs once a minute meanwhile.
  for (;;) {
    timespec minute{60, 0};
    const int signal = sigtimedwait(&signals, nullptr, &minute);
    if (signal == SIGTERM || signal == SIGINT) {
      spdlog::info("signal {}: draining", signal);
      break;
    }
    if (config.store.retention.max_age || config.store.retention.max_total_bytes) {
      framestore::Result<store::RetentionReport> report =
          captures->ApplyRetention(std::chrono::system_clock::now());
      if (!report.ok())
        spdlog::error("retention: {}", report.status().message());
      else if (!report->deleted.empty())
        spdlog::info("retention deleted {} captures ({} bytes)", report->deleted.size(),
                     report->bytes_freed);
    }
  }
  sd_notify(0, "STOPPING=1\nSTATUS=draining");
  service.BeginDrain();
  if (listener) listener->Stop();
  events.Close();
  // Calls under way (a grab being stored) finish; then the rest are cancelled.
  server->Shutdown(std::chrono::system_clock::now() + config.drain_timeout);
  server->Wait();
  spdlog::info("bslsd stopped after {} acknowledged grabs", service.grabs_acknowledged());
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"bslsd: the BSLS capture daemon"};
  std::optional<std::string> config_path;
  std::vector<std::string> overrides;
  bool check = false;
  std::string backend, store_root, socket, tcp;
  app.add_option("-c,--config", config_path, "configuration file (YAML)");
  app.add_option("--set", overrides, "override a key, e.g. --set framestore.backend=usb")
      ->take_all();
  app.add_flag("--check-config", check, "check the configuration, print it and exit");
  app.add_option("--backend", backend, "framestore.backend: simulated, isa, emulated-isa, usb");
  app.add_option("--store", store_root, "store.root: the capture store's directory");
  app.add_option("--socket", socket, "listen.unix_socket");
  app.add_option("--tcp", tcp, "listen.tcp (host:port, mutual TLS)");
  app.set_version_flag("--version", BSLS_VERSION);
  CLI11_PARSE(app, argc, argv);
  if (!backend.empty()) overrides.push_back("framestore.backend=" + backend);
  if (!store_root.empty()) overrides.push_back("store.root=" + store_root);
  if (!socket.empty()) overrides.push_back("listen.unix_socket=" + socket);
  if (!tcp.empty()) overrides.push_back("listen.tcp=" + tcp);

  bsls::framestore::Result<bsls::bslsd::Config> config =
      bsls::bslsd::LoadConfig(config_path, overrides);
  if (!config.ok()) {
    std::fprintf(stderr, "bslsd: %s\n", config.status().message().c_str());
    return kExitConfig;
  }
  if (check) {
    bsls::framestore::Result<bsls::service::RolePolicy> policy =
        bsls::bslsd::ResolveRoles(config->roles);
    if (!policy.ok()) {
      std::fprintf(stderr, "bslsd: %s\n", policy.status().message().c_str());
      return kExitConfig;
    }
    std::fputs(bsls::bslsd::Dump(*config).c_str(), stdout);
    std::fputs("# configuration OK\n", stdout);
    return 0;
  }
  return Run(*config);
}
