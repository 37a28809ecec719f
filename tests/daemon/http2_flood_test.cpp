// bslsd's memory after HTTP/2 floods (issue 26, "Memory": the outside probe
// saw 700 MB resident after ping and rapid-reset floods; memory after a
// flood must return within 20 % of its level before). A real bslsd on its
// plaintext Unix socket is flooded with raw HTTP/2 frames
// (bsls/testing/http2_flood.h) over several connections at once:
//  - PING frames, thousands per connection, answered with acknowledgements
//    until the ping strikes (listen.max_ping_strikes) cost the connection a
//    GOAWAY, then on a new connection;
//  - rapid reset: HEADERS opening a GetStatus call followed at once by its
//    RST_STREAM, stream after stream (each reset stream frees its place
//    under max_concurrent_streams, so the peer opens streams without bound).
// Its resident memory (VmRSS) is read at rest before, sampled during, and
// after each flood is waited for until it is within 20 % of before (at
// most kSettle: the daemon hands freed memory back every 10 s); then it
// must answer GetStatus.
#include "bsls/testing/http2_flood.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <thread>

#include "bsls/testing/raw_connections.h"
#include "daemon_process.h"
#include "processd_process.h"

namespace bsls::testing {
namespace {

using std::chrono::milliseconds;
using std::chrono::seconds;
namespace h2 = http2;

constexpr double kRssGrowth = 1.20;       // after a flood, within 20 % of before
constexpr auto kSettle = seconds(30);     // three of bslsd's 10 s trims
constexpr auto kFloodTime = seconds(10);  // each flood
constexpr int kFloodConnections = 8;      // at once
constexpr int kPingsPerBatch = 512;       // PING frames per write
constexpr int kResetsPerBatch = 128;      // HEADERS + RST_STREAM pairs per write
constexpr char kGetStatus[] = "/bsls.v1.CaptureDaemon/GetStatus";

// The largest VmRSS of `pid` seen while `work` runs (sampled every 100 ms), KiB.
template <typename Work>
long PeakRssWhile(pid_t pid, Work&& work) {
  std::atomic<bool> done{false};
  std::atomic<long> peak{processing::test::ResidentKib(pid)};
  std::thread sampler([&] {
    while (!done) {
      peak = std::max(peak.load(), processing::test::ResidentKib(pid));
      std::this_thread::sleep_for(milliseconds(100));
    }
  });
  work();
  done = true;
  sampler.join();
  return peak;
}

// Waits up to kSettle for `pid`'s resident memory to come back within
// kRssGrowth of `before_kib`; the last reading.
long SettledRss(pid_t pid, long before_kib) {
  const auto until = std::chrono::steady_clock::now() + kSettle;
  long rss = processing::test::ResidentKib(pid);
  while (rss > before_kib * kRssGrowth && std::chrono::steady_clock::now() < until) {
    std::this_thread::sleep_for(milliseconds(250));
    rss = processing::test::ResidentKib(pid);
  }
  return rss;
}

TEST(BslsdHttp2Flood, MemoryReturnsWithin20PercentAfterPingAndRapidResetFloods) {
  const fs::path dir = MakeDaemonDir("http2_flood");
  // This test's user may call GetStatus (viewer), whoever runs it.
  DaemonProcess daemon(
      dir, WriteDaemonConfig(dir, "roles:\n  viewer: ['" + std::to_string(::geteuid()) + "']\n"));
  ASSERT_TRUE(daemon.ready()) << daemon.Log();
  const pid_t pid = daemon.pid();
  auto status_ok = [&] {
    v1::DeviceStatus status;
    return daemon.Stub()->GetStatus(Deadline(milliseconds(5000)).get(), {}, &status).ok();
  };
  // At rest: a few calls made (gRPC's first-call allocations), then one trim.
  for (int i = 0; i < 5; ++i) ASSERT_TRUE(status_ok());
  std::this_thread::sleep_for(seconds(11));
  const auto connect = [&daemon] { return ConnectUnixAs(0, daemon.socket().string()); };

  struct Case {
    const char* name;
    std::function<std::string(std::uint32_t*)> batch;
  };
  const std::vector<Case> floods = {{"ping flood",
                                     [](std::uint32_t*) {
                                       std::string frames;
                                       for (int i = 0; i < kPingsPerBatch; ++i)
                                         frames += h2::Ping(static_cast<std::uint64_t>(i));
                                       return frames;
                                     }},
                                    {"rapid-reset flood", [](std::uint32_t* next_stream) {
                                       std::string frames;
                                       for (int i = 0; i < kResetsPerBatch; ++i, *next_stream += 2)
                                         frames += h2::CallHeaders(*next_stream, kGetStatus) +
                                                   h2::Reset(*next_stream);
                                       return frames;
                                     }}};
  for (const Case& flood : floods) {
    SCOPED_TRACE(flood.name);
    const long before = processing::test::ResidentKib(pid);
    h2::FloodCounts counts;
    const long peak = PeakRssWhile(
        pid, [&] { counts = h2::Flood(connect, flood.batch, kFloodConnections, kFloodTime); });
    const long after = SettledRss(pid, before);
    std::printf(
        "%s: %ld connections, %ld frames sent, %ld ping acks, %ld GOAWAYs, %ld KiB read; "
        "RSS before %ld KiB, peak %ld KiB, after %ld KiB\n",
        flood.name, counts.connections, counts.frames, counts.ping_acks, counts.goaways,
        counts.bytes_read / 1024, before, peak, after);
    std::fflush(stdout);
    ASSERT_FALSE(daemon.exited()) << flood.name << " ended bslsd\n" << daemon.Log();
    // The flood reached the daemon's HTTP/2 layer: it answered.
    EXPECT_GT(counts.frames, 10000);
    EXPECT_GT(counts.bytes_read, 0);
    EXPECT_LE(after, before * kRssGrowth)
        << flood.name << ": resident memory " << after << " KiB, " << before << " KiB before";
    EXPECT_TRUE(status_ok()) << flood.name << ": GetStatus not served afterwards";
  }
  EXPECT_EQ(daemon.Terminate(seconds(10)), 0) << daemon.Log();
}

}  // namespace
}  // namespace bsls::testing
