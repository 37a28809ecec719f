// Preview to four clients at once, one of them reading slowly: the others
// keep the camera's 25 frames/s; a reader that reads nothing gives its slot
// back; 64 streams, two of them stalled, on threads that do not grow with
// the streams (the callback API holds none per stream). Timing depends on the
// machine, so this test is labelled `timing` (not run under the sanitizers).
#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <cstdio>
#include <fstream>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "daemon_process.h"

namespace bsls::testing {
namespace {

using std::chrono::milliseconds;
using Clock = std::chrono::steady_clock;

struct StreamFigures {
  int frames = 0;  // received inside the window
  std::uint64_t dropped = 0;
  // Camera sequence numbers of the first and last frame inside the window:
  // the frames the camera made meanwhile, whoever read them.
  std::uint64_t first_sequence = 0;
  std::uint64_t last_sequence = 0;
  bool ok = true;

  // Frames the camera made from the first to the last one received.
  std::uint64_t Made() const { return frames ? last_sequence - first_sequence + 1 : 0; }
};

// A client connection whose receive window holds about one 512 x 512
// frame: otherwise the transport reads ahead into a window it grows on its
// own (many frames on a loaded machine), and the daemon, never held up, has
// nothing to drop or stall on.
grpc::ChannelArguments OneFrameWindow() {
  grpc::ChannelArguments args;
  args.SetInt(GRPC_ARG_HTTP2_BDP_PROBE, 0);
  args.SetInt(GRPC_ARG_HTTP2_STREAM_LOOKAHEAD_BYTES, 512 * 512);
  return args;
}

// bslsd for a preview test `name`: the caller is admin, at most
// `max_streams` previews, a write the reader does not take in
// `write_timeout_ms` ends its stream.
std::unique_ptr<DaemonProcess> PreviewDaemon(const std::string& name, int max_streams,
                                             int write_timeout_ms) {
  const fs::path dir = MakeDaemonDir(name);
  const fs::path config = WriteDaemonConfig(dir, "roles:\n  admin: [root]\n");
  return std::make_unique<DaemonProcess>(
      dir, config,
      std::vector<std::string>{
          "--set", "limits.max_preview_streams=" + std::to_string(max_streams), "--set",
          "limits.stream_write_timeout_ms=" + std::to_string(write_timeout_ms)});
}

// Reads previews until `end`; counts those that arrive after `window_start`.
StreamFigures ReadPreview(v1::CaptureDaemon::Stub& stub, Clock::time_point window_start,
                          Clock::time_point end, milliseconds pause) {
  StreamFigures figures;
  grpc::ClientContext context;
  context.set_deadline(std::chrono::system_clock::now() +
                       std::chrono::duration_cast<std::chrono::system_clock::duration>(
                           end - Clock::now() + std::chrono::seconds(5)));
  auto reader = stub.StreamPreview(&context, {});
  v1::PreviewFrame frame;
  while (Clock::now() < end && reader->Read(&frame)) {
    if (Clock::now() >= window_start) {
      if (figures.frames == 0) figures.first_sequence = frame.frame().sequence();
      figures.last_sequence = frame.frame().sequence();
      ++figures.frames;
      figures.dropped += frame.dropped();
    }
    if (pause.count() > 0) std::this_thread::sleep_for(pause);
  }
  context.TryCancel();
  while (reader->Read(&frame)) {
  }
  reader->Finish().IgnoreError();
  return figures;
}

// The simulated camera makes 25 frames a second. A client that reads as
// fast as it can gets every frame the camera made, however slowly a fourth
// reads: what the slow one costs the others is asserted as frames missed,
// not as a frame rate, which a loaded test machine lowers for everyone
// alike (the camera's own rate is only checked to be a preview's at all).
TEST(BslsdPreview, FourClientsOneSlowTheOthersGetEveryFrame) {
  const fs::path dir = MakeDaemonDir("preview");
  const fs::path config = WriteDaemonConfig(dir, "roles:\n  admin: [root]\n");
  DaemonProcess daemon(dir, config);
  ASSERT_TRUE(daemon.ready()) << daemon.Log();

  // Warm-up: one breathing period renders every phase of the view once.
  {
    auto stub = daemon.Stub();
    const Clock::time_point now = Clock::now();
    ReadPreview(*stub, now, now + std::chrono::seconds(5), milliseconds(0));
  }
  constexpr double kWindowSeconds = 5.0;
  const Clock::time_point start = Clock::now() + std::chrono::seconds(1);
  const Clock::time_point end = start + std::chrono::duration_cast<Clock::duration>(
                                            std::chrono::duration<double>(kWindowSeconds));
  StreamFigures figures[4];
  std::vector<std::thread> clients;
  for (int i = 0; i < 4; ++i) {
    clients.emplace_back([&, i] {
      // Each client on a connection of its own; the slow one's window
      // holds one frame.
      auto stub = daemon.Stub(i == 3 ? OneFrameWindow() : grpc::ChannelArguments());
      figures[i] = ReadPreview(*stub, start, end, i == 3 ? milliseconds(250) : milliseconds(0));
    });
  }
  for (std::thread& t : clients) t.join();
  for (int i = 0; i < 3; ++i) {
    const double fps = figures[i].frames / kWindowSeconds;
    std::printf("[ figures  ] client %d: %.1f frames/s, %d of %llu made, %llu dropped\n", i, fps,
                figures[i].frames, static_cast<unsigned long long>(figures[i].Made()),
                static_cast<unsigned long long>(figures[i].dropped));
    EXPECT_EQ(static_cast<std::uint64_t>(figures[i].frames), figures[i].Made()) << "client " << i;
    EXPECT_EQ(figures[i].dropped, 0u) << "client " << i;
    EXPECT_GE(fps, 15.0) << "client " << i;
  }
  const double slow_fps = figures[3].frames / kWindowSeconds;
  std::printf("[ figures  ] slow client: %.1f frames/s, %llu dropped\n", slow_fps,
              static_cast<unsigned long long>(figures[3].dropped));
  EXPECT_GT(figures[3].dropped, 0u);  // it was told what it missed
  EXPECT_LE(slow_fps, 5.0);
  EXPECT_EQ(daemon.Terminate(), 0) << daemon.Log();
}

// A reader that reads nothing and set no deadline would hold one of the
// preview slots for ever: a write it does not take within
// limits.stream_write_timeout_ms ends its stream with RESOURCE_EXHAUSTED,
// and the next reader gets the slot and its frames.
TEST(BslsdPreview, AReaderThatReadsNothingGivesItsSlotBack) {
  const auto started = PreviewDaemon("preview_stalled", 1, 1000);
  DaemonProcess& daemon = *started;
  ASSERT_TRUE(daemon.ready()) << daemon.Log();

  // The stalled reader: no deadline, a receive window of about one frame,
  // and not a single Read.
  auto stalled_stub = daemon.Stub(OneFrameWindow());
  grpc::ClientContext stalled;
  auto stalled_reader = stalled_stub->StreamPreview(&stalled, {});
  std::this_thread::sleep_for(milliseconds(300));

  // The one slot is taken at first; within a few seconds it is free again.
  bool refused_at_first = false;
  bool got_frame = false;
  const Clock::time_point until = Clock::now() + std::chrono::seconds(30);
  for (int attempt = 0; !got_frame && Clock::now() < until; ++attempt) {
    auto stub = daemon.Stub();
    auto context = Deadline(milliseconds(10000));
    auto reader = stub->StreamPreview(context.get(), {});
    v1::PreviewFrame frame;
    if (reader->Read(&frame)) {
      got_frame = frame.frame().width() > 0;
      context->TryCancel();
      while (reader->Read(&frame)) {
      }
      reader->Finish().IgnoreError();
      break;
    }
    const grpc::Status status = reader->Finish();
    EXPECT_EQ(status.error_code(), grpc::StatusCode::RESOURCE_EXHAUSTED) << status.error_message();
    if (attempt == 0) refused_at_first = true;
    std::this_thread::sleep_for(milliseconds(200));
  }
  EXPECT_TRUE(refused_at_first) << "the stalled reader did not hold the slot to begin with";
  EXPECT_TRUE(got_frame) << "the stalled reader kept the only preview slot";

  // The stalled reader, reading at last, finds its stream ended with the reason.
  v1::PreviewFrame frame;
  while (stalled_reader->Read(&frame)) {
  }
  const grpc::Status ended = stalled_reader->Finish();
  EXPECT_EQ(ended.error_code(), grpc::StatusCode::RESOURCE_EXHAUSTED) << ended.error_message();
  EXPECT_NE(ended.error_message().find("stream_write_timeout_ms"), std::string::npos)
      << ended.error_message();
  EXPECT_EQ(daemon.Terminate(), 0) << daemon.Log();
}

// Threads of process `pid` now (/proc/PID/status).
int ThreadsOf(pid_t pid) {
  std::ifstream status("/proc/" + std::to_string(pid) + "/status");
  for (std::string line; std::getline(status, line);)
    if (line.rfind("Threads:", 0) == 0) return std::stoi(line.substr(8));
  return -1;
}

// 64 preview streams at once, 2 of them stalled (they never read), the
// other 62 each at the full rate they asked for (every fifth frame of the
// camera's, so that 62 copies of 512 x 512 fit the machine: none missed
// one, and all took as many), and bslsd's thread
// count does not grow with the streams: 8 streams and 64 take the same
// threads within a few.
TEST(BslsdPreview, SixtyFourStreamsTwoStalledTheOthersAtFullRateOnFlatThreads) {
  const auto started = PreviewDaemon("preview_64", 64, 60000);
  DaemonProcess& daemon = *started;
  ASSERT_TRUE(daemon.ready()) << daemon.Log();
  constexpr int kStreams = 64, kStalled = 2, kChannels = 6;
  constexpr std::uint32_t kEvery = 5;
  // Warm-up: the capture thread and one breathing period of the view.
  {
    auto stub = daemon.Stub();
    const Clock::time_point now = Clock::now();
    ReadPreview(*stub, now, now + std::chrono::seconds(3), milliseconds(0));
  }

  // The stalled streams, each on a connection of its own with a receive
  // window of about one frame, never read.
  std::vector<std::unique_ptr<v1::CaptureDaemon::Stub>> stalled_stubs;
  std::vector<std::unique_ptr<grpc::ClientContext>> stalled_contexts;
  std::vector<std::unique_ptr<grpc::ClientReader<v1::PreviewFrame>>> stalled;
  for (int i = 0; i < kStalled; ++i) {
    stalled_stubs.push_back(daemon.Stub(OneFrameWindow()));
    stalled_contexts.push_back(std::make_unique<grpc::ClientContext>());
    stalled.push_back(stalled_stubs.back()->StreamPreview(stalled_contexts.back().get(), {}));
  }

  // The readers, spread over a few connections; each counts what arrives
  // inside the window.
  std::vector<std::unique_ptr<v1::CaptureDaemon::Stub>> stubs;
  for (int c = 0; c < kChannels; ++c) stubs.push_back(daemon.Stub(grpc::ChannelArguments()));
  std::atomic<int> open{0};
  std::atomic<bool> stop{false};
  std::vector<int> frames(kStreams - kStalled, 0);
  std::vector<std::uint64_t> dropped(kStreams - kStalled, 0);
  std::atomic<Clock::rep> window_start{Clock::time_point::max().time_since_epoch().count()};
  std::vector<std::thread> readers;
  int threads_at_8 = -1;
  for (int i = 0; i < kStreams - kStalled; ++i) {
    readers.emplace_back([&, i] {
      grpc::ClientContext context;
      v1::PreviewRequest request;
      request.set_decimation(kEvery);
      auto reader = stubs[i % kChannels]->StreamPreview(&context, request);
      v1::PreviewFrame frame;
      bool counted_open = false;
      while (!stop && reader->Read(&frame)) {
        if (!counted_open) {
          ++open;
          counted_open = true;
        }
        if (Clock::now().time_since_epoch().count() >= window_start) {
          ++frames[i];
          dropped[i] += frame.dropped();
        }
      }
      context.TryCancel();
      while (reader->Read(&frame)) {
      }
      reader->Finish().IgnoreError();
    });
    // The threads with the stalled two and six readers streaming.
    if (i == 5) {
      while (open < 6) std::this_thread::sleep_for(milliseconds(10));
      std::this_thread::sleep_for(milliseconds(500));
      threads_at_8 = ThreadsOf(daemon.pid());
    }
  }
  const Clock::time_point until_open = Clock::now() + std::chrono::seconds(30);
  while (open < kStreams - kStalled && Clock::now() < until_open)
    std::this_thread::sleep_for(milliseconds(10));
  ASSERT_EQ(open, kStreams - kStalled) << "readers that got a frame";
  std::this_thread::sleep_for(milliseconds(500));
  const int threads_at_64 = ThreadsOf(daemon.pid());

  constexpr double kWindowSeconds = 4.0;
  const Clock::time_point start = Clock::now() + std::chrono::seconds(1);
  window_start = start.time_since_epoch().count();
  // The camera's own rate while the streams run: what "full rate" means.
  std::this_thread::sleep_until(start + std::chrono::seconds(2));
  v1::DeviceStatus status;
  ASSERT_TRUE(daemon.Stub()->GetStatus(Deadline(milliseconds(5000)).get(), {}, &status).ok());
  std::this_thread::sleep_until(start + std::chrono::duration_cast<Clock::duration>(
                                            std::chrono::duration<double>(kWindowSeconds)));
  // Racy by a frame at most; the bound has slack.
  const std::vector<int> counted = frames;
  const std::vector<std::uint64_t> missed = dropped;
  stop = true;
  for (auto& context : stalled_contexts) context->TryCancel();
  for (std::thread& t : readers) t.join();
  for (auto& reader : stalled) reader->Finish().IgnoreError();

  const double full_rate = status.preview_rate_hz() / kEvery;
  const auto [fewest, most] = std::minmax_element(counted.begin(), counted.end());
  std::uint64_t most_missed = 0;
  for (std::uint64_t n : missed) most_missed = std::max(most_missed, n);
  std::printf(
      "[ figures  ] %d streams (%d stalled): camera %.1f frames/s; readers %.2f-%.2f "
      "frames/s (the camera's over 5: %.2f), at most %llu frames missed; bslsd threads "
      "%d with 8 streams, %d with 64\n",
      kStreams, kStalled, status.preview_rate_hz(), *fewest / kWindowSeconds,
      *most / kWindowSeconds, full_rate, static_cast<unsigned long long>(most_missed), threads_at_8,
      threads_at_64);
  // Every reader took every frame it asked for (the stalled two hold up
  // nobody): none missed one, and all took as many within a frame or two
  // (the window's edges). The camera's own rate moves with the machine's
  // load, so the readers are held to each other and to what they missed,
  // not to a rate.
  EXPECT_EQ(most_missed, 0u);
  EXPECT_GT(*fewest, 0);
  EXPECT_GE(*fewest, *most - 2);
  EXPECT_GT(threads_at_8, 0);
  EXPECT_LE(threads_at_64, threads_at_8 + 4) << "threads grew with the streams";
  EXPECT_EQ(daemon.Terminate(), 0) << daemon.Log();
}

}  // namespace
}  // namespace bsls::testing
