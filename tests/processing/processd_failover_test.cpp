// Failover across bsls-processd replicas: three
// replicas as real processes on loopback TCP, one channel with round_robin,
// 100 ReconstructSession calls through ProcessingClient with its retries;
// once about 20 have completed, one replica that has a call running and
// another waiting is killed with SIGKILL. Every session must still end with
// a Result, and no call begun after the kill may be served by the dead
// replica.
#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <map>
#include <mutex>
#include <set>
#include <thread>

#include "bsls/testing/build_paths.h"
#include "processd_process.h"
#include "replica_inputs.h"

namespace bsls::processing::test {
namespace {

using Clock = std::chrono::steady_clock;

constexpr int kSessions = 100;
constexpr int kKillAfter = 20;     // sessions completed before the kill
constexpr int kClientThreads = 5;  // > 3: some replica always has a call waiting

// What one session gave.
struct SessionRecord {
  Clock::time_point start, end;
  grpc::Status status;
  bool has_result = false;
  bool has_surface = false;  // the joined surface.ply came with it
  std::string replica;
  std::string tag;
  int attempts = 0;
};

// GetServerInfo of one replica on a channel of its own (no balancing).
grpc::Status ReplicaInfo(const ProcessdProcess& replica, v1::ServerInfo* info) {
  auto stub = v1::Processing::NewStub(
      grpc::CreateChannel(replica.address(), grpc::InsecureChannelCredentials()));
  grpc::ClientContext context;
  context.set_deadline(std::chrono::system_clock::now() + std::chrono::seconds(10));
  return stub->GetServerInfo(&context, {}, info);
}

// Every one of 100 sessions completes with a Result although a replica is
// killed mid-run, and the dead replica serves nothing begun after its death.
TEST(ProcessdFailover, HundredSessionsCompleteWhenAReplicaIsKilled) {
  const auto test_start = Clock::now();
  const v1::ReconstructSessionRequest request = SessionRequestOf(LightSessionInputs());
  const double inputs_s = std::chrono::duration<double>(Clock::now() - test_start).count();

  const fs::path folder = MakeTempFolder("bsls_failover_");
  std::vector<std::unique_ptr<ProcessdProcess>> replicas;
  for (const char* name : {"r0", "r1", "r2"}) {
    replicas.push_back(
        std::make_unique<ProcessdProcess>(bsls::testing::ProcessdPath(), folder, name, 1));
    ASSERT_TRUE(replicas.back()->ready()) << name << ": " << replicas.back()->Log();
  }
  ClientOptions options;
  options.target = RoundRobinTarget(replicas);
  options.timeout = std::chrono::minutes(5);  // each attempt; AddressSanitizer is slow
  auto client = std::make_unique<ProcessingClient>(OpenProcessingChannel(options), options);

  std::vector<SessionRecord> records(kSessions);
  std::atomic<int> next{0}, completed{0};
  std::vector<std::thread> threads;
  const auto run_start = Clock::now();
  for (int t = 0; t < kClientThreads; ++t)
    threads.emplace_back([&] {
      for (int i; (i = next++) < kSessions;) {
        v1::ReconstructSessionRequest mine = request;
        mine.set_request_tag("session-" + std::to_string(i));
        SessionRecord& r = records[static_cast<std::size_t>(i)];
        r.start = Clock::now();
        const WorkOutcome out = client->ReconstructSession(mine);
        r.end = Clock::now();
        r.status = out.status;
        r.attempts = out.attempts;
        r.has_result = out.status.ok() && !out.result.replica().empty();
        r.has_surface = out.files.count("surface.ply") && !out.files.at("surface.ply").empty();
        r.replica = out.result.replica();
        r.tag = out.result.request_tag();
        ++completed;
      }
    });

  // The victim: a replica with a call running and one waiting, so that a
  // call is certainly in flight on it when it dies.
  while (completed < kKillAfter && next < kSessions)
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  ProcessdProcess* victim = nullptr;
  bool victim_had_waiting = false;
  const auto search_until = Clock::now() + std::chrono::seconds(30);
  while (!victim && Clock::now() < search_until && next < kSessions) {
    for (auto& replica : replicas) {
      v1::ServerInfo info;
      if (ReplicaInfo(*replica, &info).ok() && info.busy() >= 1 && info.waiting() >= 1) {
        victim = replica.get();
        victim_had_waiting = true;
        break;
      }
    }
  }
  if (!victim) victim = replicas[1].get();  // reported below; the run still counts
  const int completed_at_kill = completed;
  victim->Kill();
  const auto kill_time = Clock::now();
  EXPECT_EQ(victim->signal(), SIGKILL);

  for (std::thread& t : threads) t.join();
  const double run_s = std::chrono::duration<double>(Clock::now() - run_start).count();

  // All 100 completed with their own Result.
  std::map<std::string, int> before, after;  // results by replica, by start vs. kill
  int retried = 0, begun_after = 0, most_attempts = 0;
  for (int i = 0; i < kSessions; ++i) {
    const SessionRecord& r = records[static_cast<std::size_t>(i)];
    EXPECT_TRUE(r.status.ok()) << "session " << i << ": " << r.status.error_code() << " "
                               << r.status.error_message() << " after " << r.attempts
                               << " attempts";
    EXPECT_TRUE(r.has_result) << "session " << i;
    EXPECT_TRUE(r.has_surface) << "session " << i;
    EXPECT_EQ(r.tag, "session-" + std::to_string(i));
    retried += r.attempts > 1;
    most_attempts = std::max(most_attempts, r.attempts);
    if (r.start > kill_time) {
      ++begun_after;
      ++after[r.replica];
      // Served by a survivor.
      EXPECT_NE(r.replica, victim->name()) << "session " << i << " begun after the kill";
    } else {
      ++before[r.replica];
    }
  }
  // The run really spanned the kill: sessions were begun after it, and the
  // call in flight on the victim came back through a retry.
  EXPECT_GT(begun_after, 0);
  EXPECT_GE(completed_at_kill, kKillAfter);
  EXPECT_LT(completed_at_kill, kSessions);
  if (victim_had_waiting) {
    EXPECT_GE(retried, 1);
  }
  for (auto& replica : replicas) {
    if (replica.get() != victim) {
      EXPECT_GT(after[replica->name()], 0) << replica->name() << " served nothing after the kill";
    }
  }

  std::string figures;
  for (auto& replica : replicas)
    figures += " " + replica->name() + " " + std::to_string(before[replica->name()]) + "/" +
               std::to_string(after[replica->name()]);
  std::printf(
      "inputs %.1f s; 100 sessions in %.1f s; killed %s after %d (had a waiting call: %s); "
      "%d sessions retried (at most %d attempts); results by replica (begun before/after the "
      "kill):%s\n",
      inputs_s, run_s, victim->name().c_str(), completed_at_kill, victim_had_waiting ? "yes" : "no",
      retried, most_attempts, figures.c_str());

  // The survivors drain cleanly (under the sanitizers: no leak at exit). The
  // channel goes first: a replica's drain waits for open connections.
  client.reset();
  const auto stop_start = Clock::now();
  for (auto& replica : replicas) {
    if (replica.get() != victim) {
      EXPECT_EQ(replica->Terminate(), 0) << replica->name() << ": " << replica->Log();
    }
  }
  std::printf("survivors stopped in %.1f s\n",
              std::chrono::duration<double>(Clock::now() - stop_start).count());
  std::error_code ec;
  if (!HasFailure()) fs::remove_all(folder, ec);
}

}  // namespace
}  // namespace bsls::processing::test
