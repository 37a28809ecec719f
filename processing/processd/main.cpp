// bsls-processd: the BSLS processing service. Runs unprivileged;
// configuration errors exit 78 (EX_CONFIG) so systemd does not restart into
// the same mistake.
#include <signal.h>
#include <spdlog/sinks/stdout_color_sinks.h>
#include <spdlog/spdlog.h>
#include <systemd/sd-daemon.h>

#include <CLI/CLI.hpp>
#include <cstdio>
#include <iostream>

#include "bsls/rpc/server_limits.h"
#include "bsls/rpc/tls.h"
#include "config.h"
#include "server.h"

#ifndef BSLS_VERSION
#define BSLS_VERSION "unknown"
#endif

namespace {

constexpr int kExitRuntime = 1;
constexpr int kExitConfig = 78;

int Run(const bsls::processd::Config& config) {
  spdlog::set_level(spdlog::level::from_str(config.log_level));
  // Signals are taken by sigwait below; every thread started from here inherits the mask.
  sigset_t signals;
  sigemptyset(&signals);
  sigaddset(&signals, SIGTERM);
  sigaddset(&signals, SIGINT);
  pthread_sigmask(SIG_BLOCK, &signals, nullptr);

  std::unique_ptr<bsls::processd::Server> server;
  try {
    server = bsls::processd::Server::Start(config, BSLS_VERSION);
  } catch (const bsls::processd::ConfigError& e) {
    spdlog::critical("{}", e.what());
    return kExitConfig;
  } catch (const bsls::rpc::TlsFileError& e) {
    spdlog::critical("{}", e.what());
    return kExitConfig;
  } catch (const std::exception& e) {
    spdlog::critical("{}", e.what());
    return kExitRuntime;
  }
  // Scripts and tests that start a replica on port 0 read the port here.
  if (server->tcp_port() != 0) std::printf("tcp_port=%d\n", server->tcp_port());
  std::fflush(stdout);
  sd_notify(0, "READY=1\nSTATUS=serving");
  int signal = 0;
  sigwait(&signals, &signal);
  spdlog::info("signal {}: draining", signal);
  sd_notify(0, "STOPPING=1\nSTATUS=draining");
  server->Drain();
  const bsls::processing::WorkPoolStats stats = server->service().Stats();
  spdlog::info("bsls-processd stopped after {} work calls ({} refused as busy)", stats.completed,
               stats.rejected);
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  // Memory comes back after a burst of work (the pool also trims after each call).
  bsls::rpc::TuneAllocator();
  // Logs on stderr: stdout carries only the tcp_port=N line scripts read.
  spdlog::set_default_logger(spdlog::stderr_color_mt("bsls-processd"));
  CLI::App app{
      "bsls-processd: the BSLS processing service (frames to junctions, surfaces, "
      "measurements and calibrations)"};
  std::string config_path;
  std::vector<std::string> overrides;
  bool check = false;
  std::string socket, tcp, replica;
  int workers = -1;
  app.add_option("-c,--config", config_path, "configuration file (YAML)");
  app.add_option("--set", overrides, "override a key, e.g. --set workers=4")->take_all();
  app.add_flag("--check-config", check, "check the configuration, print it and exit");
  app.add_option("--socket", socket, "listen.unix_socket (\"\" for none)");
  app.add_option("--tcp", tcp, "listen.tcp (host:port; mutual TLS unless plaintext_loopback)");
  app.add_option("--replica", replica, "replica: the name in results and logs");
  app.add_option("--workers", workers, "workers: work that runs at once (0: one per core)");
  app.set_version_flag("--version", BSLS_VERSION);
  CLI11_PARSE(app, argc, argv);

  // Shorthand options are overrides of their keys, applied last.
  if (app.count("--socket")) overrides.push_back("listen.unix_socket=\"" + socket + "\"");
  if (app.count("--tcp")) overrides.push_back("listen.tcp=\"" + tcp + "\"");
  if (app.count("--replica")) overrides.push_back("replica=\"" + replica + "\"");
  if (app.count("--workers")) overrides.push_back("workers=" + std::to_string(workers));
  bsls::processd::Config config;
  try {
    config = bsls::processd::LoadConfig(
        config_path.empty() ? std::nullopt : std::optional<std::string>(config_path), overrides);
  } catch (const bsls::processd::ConfigError& e) {
    std::cerr << "bsls-processd: " << e.what() << "\n";
    return kExitConfig;
  }
  if (check) {
    std::cout << bsls::processd::Dump(config);
    return 0;
  }
  return Run(config);
}
