// Sessions per second of bsls-processd replicas: ReconstructSession
// of both simulated 512 x 512 faces with both calibrations inline (the
// request of tests/processing/service_fixture.h), through ONE channel with
// round_robin over 1, 2 and 3 replicas. Each replica is the real executable
// on plain loopback TCP with one worker; two client threads per replica keep
// each one with a call running and another waiting.
//
// Counters: items_per_second (sessions per second of wall time);
// vs_1_replica, that rate over the 1-replica rate of the same run; the CPU
// the replicas and this client used per wall second (cores busy) and per
// session; attempts per session and the replicas' RESOURCE_EXHAUSTED answers
// (retried by the client); the share of the busiest and the idlest replica. docs/benchmarks.md has
// the figures.
#include <benchmark/benchmark.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "bsls/testing/build_paths.h"
#include "processd_process.h"
#include "service_fixture.h"

namespace bsls::processing::test {
namespace {

using Clock = std::chrono::steady_clock;

constexpr int kSessionsPerIteration = 48;
constexpr int kClientThreadsPerReplica = 2;

// The session request: both faces and both calibrations, built once (the
// calibration sessions are rendered on first use, before any replica runs).
const v1::ReconstructSessionRequest& Request() {
  static const v1::ReconstructSessionRequest request = [] {
    v1::ReconstructSessionRequest r;
    *r.mutable_left() = FrameMessage(FaceFrame(pattern::Side::kLeft));
    *r.mutable_right() = FrameMessage(FaceFrame(pattern::Side::kRight));
    *r.mutable_left_calibration() = ProcessingClient::Inline(CalibrationYaml(pattern::Side::kLeft));
    *r.mutable_right_calibration() =
        ProcessingClient::Inline(CalibrationYaml(pattern::Side::kRight));
    return r;
  }();
  return request;
}

// Sessions per second of the 1-replica run, the baseline of the ratio.
double& BaselineRate() {
  static double rate = 0.0;
  return rate;
}

// A replica's ServerInfo (completed and rejected calls so far; empty on error).
v1::ServerInfo Info(const ProcessdProcess& replica) {
  auto stub = v1::Processing::NewStub(
      grpc::CreateChannel(replica.address(), grpc::InsecureChannelCredentials()));
  grpc::ClientContext context;
  context.set_deadline(std::chrono::system_clock::now() + std::chrono::seconds(10));
  v1::ServerInfo info;
  stub->GetServerInfo(&context, {}, &info);
  return info;
}

// `d` in seconds.
double Seconds(Clock::duration d) { return std::chrono::duration<double>(d).count(); }

// ReconstructSession through round_robin over state.range(0) replicas.
void BM_ReconstructSessionReplicas(benchmark::State& state) {
  const int n = static_cast<int>(state.range(0));
  const v1::ReconstructSessionRequest& request = Request();
  const fs::path folder = MakeTempFolder("bsls_replicas_bench_");
  std::vector<std::unique_ptr<ProcessdProcess>> replicas;
  for (int i = 0; i < n; ++i) {
    replicas.push_back(std::make_unique<ProcessdProcess>(
        bsls::testing::ProcessdPath(), folder, "r" + std::to_string(i), 1,
        std::vector<std::string>{"--set", "log_level=warn"}));
    if (!replicas.back()->ready()) {
      state.SkipWithError(("replica did not start: " + replicas.back()->Log()).c_str());
      return;
    }
  }
  ClientOptions options;
  options.target = RoundRobinTarget(replicas);
  auto client = std::make_unique<ProcessingClient>(OpenProcessingChannel(options), options);
  const int threads = kClientThreadsPerReplica * n;

  // Runs `sessions` sessions on `threads` client threads; counts failures
  // and attempts.
  std::atomic<long long> failures{0}, attempts{0};
  auto run = [&](int sessions) {
    std::atomic<int> next{0};
    std::vector<std::thread> pool;
    for (int t = 0; t < threads; ++t)
      pool.emplace_back([&] {
        while (next++ < sessions) {
          const WorkOutcome out = client->ReconstructSession(request);
          failures += !out.status.ok();
          attempts += out.attempts;
        }
      });
    for (std::thread& t : pool) t.join();
  };

  // Warm-up until every replica has served (round_robin connected to all,
  // calibrations cached, thread pools started).
  for (int round = 0; round < 20; ++round) {
    run(threads);
    bool all = true;
    for (auto& r : replicas) all = all && Info(*r).completed() >= 2;
    if (all) break;
  }
  failures = 0;
  attempts = 0;
  std::vector<v1::ServerInfo> before;
  for (auto& r : replicas) before.push_back(Info(*r));
  double replica_cpu = 0.0;
  for (auto& r : replicas) replica_cpu -= CpuSeconds(r->pid());
  double client_cpu = -CpuSeconds(::getpid());
  Clock::duration wall{};

  for (auto _ : state) {
    const auto start = Clock::now();
    run(kSessionsPerIteration);
    wall += Clock::now() - start;
  }

  for (auto& r : replicas) replica_cpu += CpuSeconds(r->pid());
  client_cpu += CpuSeconds(::getpid());
  long long most = 0, least = -1, rejected = 0;
  for (std::size_t i = 0; i < replicas.size(); ++i) {
    const v1::ServerInfo after = Info(*replicas[i]);
    const long long served = static_cast<long long>(after.completed() - before[i].completed());
    most = std::max(most, served);
    least = least < 0 ? served : std::min(least, served);
    rejected += static_cast<long long>(after.rejected() - before[i].rejected());
  }
  const double sessions = static_cast<double>(state.iterations()) * kSessionsPerIteration;
  const double rate = sessions / Seconds(wall);
  if (n == 1) BaselineRate() = rate;
  state.SetItemsProcessed(static_cast<std::int64_t>(sessions));
  if (BaselineRate() > 0) state.counters["vs_1_replica"] = rate / BaselineRate();
  state.counters["client_threads"] = threads;
  state.counters["replica_cpu_cores"] = replica_cpu / Seconds(wall);
  state.counters["client_cpu_cores"] = client_cpu / Seconds(wall);
  state.counters["replica_cpu_ms_per_session"] = 1000.0 * replica_cpu / sessions;
  state.counters["client_cpu_ms_per_session"] = 1000.0 * client_cpu / sessions;
  state.counters["attempts_per_session"] = static_cast<double>(attempts) / sessions;
  state.counters["failures"] = static_cast<double>(failures);
  state.counters["rejected_busy"] = static_cast<double>(rejected);  // RESOURCE_EXHAUSTED answers
  state.counters["busiest_share"] = static_cast<double>(most) / sessions;
  state.counters["idlest_share"] = static_cast<double>(least) / sessions;
  if (failures > 0) state.SkipWithError("some sessions failed");

  client.reset();  // a replica's drain waits for open connections
  for (auto& r : replicas) r->Terminate();
  std::error_code ec;
  fs::remove_all(folder, ec);
}

BENCHMARK(BM_ReconstructSessionReplicas)
    ->ArgName("replicas")
    ->Arg(1)
    ->Arg(2)
    ->Arg(3)
    ->Iterations(3)
    ->UseRealTime()
    ->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace bsls::processing::test

BENCHMARK_MAIN();
