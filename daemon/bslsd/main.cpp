// bslsd: the BSLS capture daemon. Owns the framestore and the slide
// controller, keeps every grab durably, and serves proto/bsls/v1/capture.proto
// on a Unix socket (roles from SO_PEERCRED) and, when configured, on TCP with
// mutual TLS.
//
// Start-up order matters for least privilege: the configuration is read, the
// devices that need CAP_SYS_RAWIO and the Unix socket (with its group) are
// set up while the process has a single thread, bslsd becomes the configured
// user when started as root, every capability is dropped (bslsd refuses to
// go on otherwise), and only then are threads started and network input
// parsed.
//
// Exit codes: 0 after a clean SIGTERM/SIGINT, 1 for runtime failures,
// 78 (EX_CONFIG) for what a restart cannot fix: a bad configuration, kernel
// lockdown forbidding port I/O, capabilities that cannot be dropped. The
// systemd unit lists 78 in RestartPreventExitStatus=, so a misconfigured
// daemon fails once with its cause instead of restart-looping.
#include <grp.h>
#include <signal.h>
#include <spdlog/spdlog.h>
#include <systemd/sd-daemon.h>
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <memory>
#include <optional>

#include "bsls/rpc/server_limits.h"
#include "config.h"
#include "daemon.h"
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
    if (now - last <
        std::chrono::duration_cast<std::chrono::steady_clock::duration>(interval_).count())
      return;
    last_ = now;
    sd_notify(0, "WATCHDOG=1");
  }

 private:
  std::chrono::microseconds interval_{0};
  std::atomic<std::chrono::steady_clock::rep> last_{0};
};

int Run(const bslsd::Config& config) {
  spdlog::set_level(spdlog::level::from_str(config.log_level));
  if (Result<service::RolePolicy> policy = bslsd::ResolveRoles(config.roles); !policy.ok()) {
    spdlog::critical("{}", policy.status().message());
    return kExitConfig;
  }

  // Started as root, bslsd becomes `user` (never serves as root by accident).
  std::optional<bslsd::Identity> identity;
  if (::geteuid() == 0) {
    Result<bslsd::Identity> resolved = bslsd::ResolveIdentity(config.user);
    if (!resolved.ok()) {
      spdlog::critical("{}", resolved.status().message());
      return kExitConfig;
    }
    identity = std::move(resolved).value();
    if (identity->uid == 0)
      spdlog::warn(
          "user: '{}' is root: bslsd keeps uid 0 (without capabilities); for tests "
          "and development only",
          config.user);
  }

  // 1. Devices that need a privilege, and the socket (its group may be one
  // the user is not in), while single-threaded.
  Result<bslsd::PrivilegedDevices> privileged = bslsd::OpenPrivileged(config);
  if (!privileged.ok()) {
    spdlog::critical("{}", privileged.status().message());
    return privileged.status().code() == ErrorCode::kPermissionDenied ? kExitConfig : kExitRuntime;
  }
  Result<std::unique_ptr<service::UnixListener>> listener = bslsd::OpenUnixListener(config);
  if (!listener.ok()) {
    spdlog::critical("{}", listener.status().message());
    return listener.status().code() == ErrorCode::kInvalidArgument ? kExitConfig : kExitRuntime;
  }
  // 2. No privilege from here on: the user's identity, no capabilities, no_new_privs.
  if (Status dropped = bslsd::DropAllCapabilities(identity); !dropped.ok()) {
    spdlog::critical("{}", dropped.message());
    return kExitConfig;
  }
  if (identity)
    spdlog::info("running as user '{}' (uid {}, gid {})", identity->name, identity->uid,
                 identity->gid);

  // Signals are taken by sigwait below; every thread started from here inherits the mask.
  sigset_t signals;
  sigemptyset(&signals);
  sigaddset(&signals, SIGTERM);
  sigaddset(&signals, SIGINT);
  sigaddset(&signals, SIGHUP);
  pthread_sigmask(SIG_BLOCK, &signals, nullptr);

  // 3. Everything else, then serve.
  Watchdog watchdog;
  Result<std::unique_ptr<bslsd::Daemon>> started = bslsd::Daemon::Start(
      config, std::move(privileged).value(), [&watchdog] { watchdog.Feed(); },
      std::move(listener).value());
  if (!started.ok()) {
    spdlog::critical("{}", started.status().message());
    return started.status().code() == ErrorCode::kInvalidArgument ? kExitConfig : kExitRuntime;
  }
  std::unique_ptr<bslsd::Daemon> daemon = std::move(started).value();
  spdlog::info("bslsd {} serving on {}{}", BSLS_VERSION, config.listen.unix_socket,
               daemon->tcp_port()
                   ? " and TCP port " + std::to_string(daemon->tcp_port()) + " (mutual TLS)"
                   : "");
  sd_notify(0, "READY=1\nSTATUS=serving");

  // 4. Until SIGTERM/SIGINT. Meanwhile freed memory goes back to the system
  // every 10 s (a flood of calls must not leave the daemon large), and
  // retention runs once a minute.
  auto retention_due = std::chrono::steady_clock::now() + std::chrono::minutes(1);
  for (;;) {
    timespec wait{10, 0};
    const int signal = sigtimedwait(&signals, nullptr, &wait);
    if (signal == SIGTERM || signal == SIGINT) {
      spdlog::info("signal {}: draining", signal);
      break;
    }
    rpc::ReturnFreedMemory();
    if (std::chrono::steady_clock::now() >= retention_due) {
      daemon->ApplyRetention();
      retention_due = std::chrono::steady_clock::now() + std::chrono::minutes(1);
    }
  }
  sd_notify(0, "STOPPING=1\nSTATUS=draining");
  daemon->Drain();
  spdlog::info("bslsd stopped after {} acknowledged grabs", daemon->grabs_acknowledged());
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  bsls::rpc::TuneAllocator();
  CLI::App app{"bslsd: the BSLS capture daemon"};
  std::optional<std::string> config_path;
  std::vector<std::string> overrides;
  bool check = false;
  std::string backend, store_root, socket, tcp;
  app.add_option("-c,--config", config_path, "configuration file (YAML)");
  app.add_option("--set", overrides, "override a key, e.g. --set framestore.backend=usb")
      ->take_all();
  app.add_flag("--check-config", check, "check the configuration, print it and exit");
  app.add_option("--backend", backend,
                 "framestore.backend: simulated, isa, emulated-isa, usb, emulated-usb");
  app.add_option("--store", store_root, "store.root: the capture store's directory");
  app.add_option("--socket", socket, "listen.unix_socket");
  app.add_option("--tcp", tcp, "listen.tcp (host:port, mutual TLS)");
  app.set_version_flag("--version", BSLS_VERSION);
  CLI11_PARSE(app, argc, argv);
  if (!backend.empty()) overrides.push_back("framestore.backend=" + backend);
  if (!store_root.empty()) overrides.push_back("store.root=" + store_root);
  if (!socket.empty()) overrides.push_back("listen.unix_socket=" + socket);
  if (!tcp.empty()) overrides.push_back("listen.tcp=" + tcp);

  bsls::Result<bsls::bslsd::Config> config = bsls::bslsd::LoadConfig(config_path, overrides);
  if (!config.ok()) {
    std::fprintf(stderr, "bslsd: %s\n", config.status().message().c_str());
    return kExitConfig;
  }
  if (check) {
    bsls::Result<bsls::service::RolePolicy> policy = bsls::bslsd::ResolveRoles(config->roles);
    if (!policy.ok()) {
      std::fprintf(stderr, "bslsd: %s\n", policy.status().message().c_str());
      return kExitConfig;
    }
    if (::geteuid() == 0) {
      bsls::Result<bsls::bslsd::Identity> identity = bsls::bslsd::ResolveIdentity(config->user);
      if (!identity.ok()) {
        std::fprintf(stderr, "bslsd: %s\n", identity.status().message().c_str());
        return kExitConfig;
      }
    }
    std::fputs(bsls::bslsd::Dump(*config).c_str(), stdout);
    std::fputs("# configuration OK\n", stdout);
    return 0;
  }
  return Run(*config);
}
