// Latency of a grab of both sides through bslsd: the daemon's own
// assembly in-process (bslsd::Daemon), a client on its Unix socket, each grab
// acknowledged only once stored durably. Per backend (the simulated head and
// the emulated ISA card): median and 99th percentile (counters p50_ms,
// p99_ms), and the same grab straight from the capture thread without gRPC
// or the store as the baseline of the same run (counter vs_device: how many
// times slower the whole call is).
#include <benchmark/benchmark.h>
#include <spdlog/spdlog.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include "daemon.h"

namespace bsls::bslsd {
namespace {

using Clock = std::chrono::steady_clock;

double Percentile(std::vector<double> values, double fraction) {
  if (values.empty()) return 0.0;
  std::sort(values.begin(), values.end());
  return values[static_cast<std::size_t>(fraction * static_cast<double>(values.size() - 1))];
}

std::string TempDir() {
  const char* base = std::getenv("TMPDIR");
  std::string pattern = std::string(base ? base : "/tmp") + "/bsls-daemon-bench-XXXXXX";
  return ::mkdtemp(pattern.data()) ? pattern : std::string();
}

struct Running {
  std::string dir;
  std::unique_ptr<Daemon> daemon;
  std::unique_ptr<v1::CaptureDaemon::Stub> stub;
};

// A daemon on `backend`, or nullptr with the benchmark skipped and why.
std::unique_ptr<Running> Start(Backend backend, benchmark::State& state) {
  auto running = std::make_unique<Running>();
  running->dir = TempDir();
  Config config = DefaultConfig();
  config.log_level = "off";
  spdlog::set_level(spdlog::level::off);
  config.framestore.backend = backend;
  config.store.root = running->dir + "/store";
  config.store.free_space_reserve_bytes = 64u << 20;
  config.store.verify_hashes_on_open = false;
  config.listen.unix_socket = running->dir + "/bslsd.sock";
  config.roles.members[service::Role::kAdmin] = {std::to_string(::geteuid())};
  config.slides.backend = SlideBackend::kNone;
  auto started = Daemon::Start(config, {});
  if (!started.ok()) {
    state.SkipWithError(started.status().ToString().c_str());
    return nullptr;
  }
  running->daemon = std::move(started).value();
  running->stub = v1::CaptureDaemon::NewStub(
      grpc::CreateChannel("unix:" + config.listen.unix_socket, grpc::InsecureChannelCredentials()));
  return running;
}

void Report(benchmark::State& state, const std::vector<double>& ms) {
  state.counters["p50_ms"] = Percentile(ms, 0.5);
  state.counters["p99_ms"] = Percentile(ms, 0.99);
}

// Median of the baseline per backend, for the ratio of the same run.
std::map<int, double>& DeviceMedians() {
  static std::map<int, double> medians;
  return medians;
}

// Baseline: both frames straight from the capture thread (no gRPC, no store).
void BM_GrabBothFromTheDevice(benchmark::State& state) {
  const auto backend = static_cast<Backend>(state.range(0));
  std::unique_ptr<Running> running = Start(backend, state);
  if (!running) return;
  std::vector<double> ms;
  for (auto _ : state) {
    const Clock::time_point start = Clock::now();
    auto frames = running->daemon->device().Grab(service::GrabSides::kBoth,
                                                 Clock::now() + std::chrono::seconds(30));
    const double elapsed = std::chrono::duration<double>(Clock::now() - start).count();
    if (!frames.ok()) {
      state.SkipWithError(frames.status().ToString().c_str());
      break;
    }
    state.SetIterationTime(elapsed);
    ms.push_back(elapsed * 1e3);
  }
  Report(state, ms);
  DeviceMedians()[static_cast<int>(backend)] = Percentile(ms, 0.5);
  running->daemon.reset();
  std::filesystem::remove_all(running->dir);
}

// The whole call: gRPC on the Unix socket, both grabs, the durable store.
void BM_GrabBothThroughTheDaemon(benchmark::State& state) {
  const auto backend = static_cast<Backend>(state.range(0));
  std::unique_ptr<Running> running = Start(backend, state);
  if (!running) return;
  std::vector<double> ms;
  v1::GrabRequest request;
  request.set_side(v1::GRAB_SIDE_BOTH);
  request.set_session_id("bench");
  for (auto _ : state) {
    grpc::ClientContext context;
    context.set_deadline(std::chrono::system_clock::now() + std::chrono::seconds(30));
    v1::GrabResponse reply;
    const Clock::time_point start = Clock::now();
    const grpc::Status status = running->stub->Grab(&context, request, &reply);
    const double elapsed = std::chrono::duration<double>(Clock::now() - start).count();
    if (!status.ok()) {
      state.SkipWithError(status.error_message().c_str());
      break;
    }
    state.SetIterationTime(elapsed);
    ms.push_back(elapsed * 1e3);
  }
  Report(state, ms);
  if (auto it = DeviceMedians().find(static_cast<int>(backend));
      it != DeviceMedians().end() && it->second > 0)
    state.counters["vs_device"] = Percentile(ms, 0.5) / it->second;
  running->daemon.reset();
  std::filesystem::remove_all(running->dir);
}

constexpr int kSimulated = static_cast<int>(Backend::kSimulated);
constexpr int kEmulatedIsa = static_cast<int>(Backend::kEmulatedIsa);

BENCHMARK(BM_GrabBothFromTheDevice)
    ->Arg(kSimulated)
    ->Iterations(60)
    ->UseManualTime()
    ->Unit(benchmark::kMillisecond);
BENCHMARK(BM_GrabBothThroughTheDaemon)
    ->Arg(kSimulated)
    ->Iterations(60)
    ->UseManualTime()
    ->Unit(benchmark::kMillisecond);
BENCHMARK(BM_GrabBothFromTheDevice)
    ->Arg(kEmulatedIsa)
    ->Iterations(20)
    ->UseManualTime()
    ->Unit(benchmark::kMillisecond);
BENCHMARK(BM_GrabBothThroughTheDaemon)
    ->Arg(kEmulatedIsa)
    ->Iterations(20)
    ->UseManualTime()
    ->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace bsls::bslsd

BENCHMARK_MAIN();
