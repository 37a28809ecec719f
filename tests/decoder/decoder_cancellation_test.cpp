// Decoding stops when its caller asks (bsls::Cancellation): at every stage
// of both chains, with bsls::Cancelled, and nothing half-decoded returned.
#include <gtest/gtest.h>
#include <time.h>

#include <algorithm>
#include <atomic>
#include <map>
#include <mutex>
#include <string>
#include <vector>

#include "bsls/common/cancellation.h"
#include "bsls/decoder/decoder.h"
#include "bsls/testing/hostile_frame.h"
#include "decoder_evaluation.h"

namespace bsls::decoder::test {
namespace {

// A cancellation that asks to stop from its `stop_at`-th question on, and
// counts the questions.
struct CountingCancellation {
  std::atomic<int> asked{0};
  int stop_at = 1 << 30;
  Cancellation Token() {
    return Cancellation([this] { return ++asked >= stop_at; });
  }
};

// Questions a stage may still ask once told to stop: one per band of rows
// of a 512-row frame running in parallel (bands of 64 rows) and the one that
// throws.
constexpr int kMaxBandsAfterStop = 512 / 64 + 1;

class DecoderCancellation : public ::testing::TestWithParam<DecodeChain> {
 protected:
  DecodeParams Params() const {
    DecodeParams params;
    params.chain = GetParam();
    return params;
  }
};

TEST_P(DecoderCancellation, ADefaultCancellationNeverStopsTheDecode) {
  const simulator::Frame frame = RenderFrame(SurfaceKind::kFace, Side::kLeft, 1);
  const DecodeResult r = Decode(frame.image, Side::kLeft, Params(), Cancellation());
  EXPECT_TRUE(r.ok) << r.error;
}

TEST_P(DecoderCancellation, EveryStageAsksAndStopsWhenTold) {
  const simulator::Frame frame = RenderFrame(SurfaceKind::kFace, Side::kLeft, 1);
  CountingCancellation counting;
  const DecodeResult whole = Decode(frame.image, Side::kLeft, Params(), counting.Token());
  ASSERT_TRUE(whole.ok) << whole.error;
  const int questions = counting.asked;
  // Asked after the pitch, the extraction and the interpretation at least.
  EXPECT_GE(questions, 3);
  std::map<std::string, int> stops;  // how many questions stopped the decode where
  for (int stop_at = 1; stop_at <= questions; ++stop_at) {
    CountingCancellation stopping;
    stopping.stop_at = stop_at;
    try {
      (void)Decode(frame.image, Side::kLeft, Params(), stopping.Token());
      ADD_FAILURE() << "question " << stop_at << " of " << questions << " said stop; no stop";
    } catch (const Cancelled& e) {
      // Told to stop, a stage ends at once: the bands of rows still running
      // in parallel (one question each) skip their work, and the next
      // question throws.
      EXPECT_LE(stopping.asked - stop_at, kMaxBandsAfterStop)
          << "the decode went on asking after it was told";
      EXPECT_NE(std::string(e.what()).find("cancelled during"), std::string::npos) << e.what();
      ++stops[e.what()];
    }
  }
  if (GetParam() == DecodeChain::kSkeleton) {
    // The re-centring asks inside its passes (every few thousand skeleton
    // pixels), not only once it is done: on an 8 Mpx frame it takes over
    // 100 ms.
    EXPECT_GE(stops["cancelled during the re-centring on ridges"], 3);
  }
}

// The CPU time the whole process has used, seconds: it stands still while
// the process waits for a core, so a stretch measured in it is the work done
// between two questions, whatever else the machine runs.
double ProcessCpuSeconds() {
  timespec t{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
  return static_cast<double>(t.tv_sec) + 1e-9 * static_cast<double>(t.tv_nsec);
}

// A cancellation that never stops the decode but notes when (in the
// process's CPU time) it was asked.
struct TimedCancellation {
  std::mutex mutex;
  std::vector<double> asked;
  Cancellation Token() {
    return Cancellation([this] {
      const std::lock_guard lock(mutex);
      asked.push_back(ProcessCpuSeconds());
      return false;
    });
  }
};

// No stage runs long without asking: on the slow hostile frame (8 Mpx,
// every other row noise), the longest stretch of work between two questions
// (or from the start to the first, or from the last to the end) is a small
// part of the whole decode's work. A service's deadline frees its worker
// within that stretch (ProcessingService/DeadlineInsideTheDecode). Measured
// in the process's CPU time, as a ratio of one run: it holds on a loaded
// machine and under the sanitizers alike.
TEST_P(DecoderCancellation, NoStageRunsLongWithoutAsking) {
  const cv::Mat frame = bsls::testing::HostileFrame();
  TimedCancellation timed;
  const double start = ProcessCpuSeconds();
  (void)Decode(frame, Side::kLeft, Params(), timed.Token());
  const double end = ProcessCpuSeconds();
  std::vector<double> times = timed.asked;
  std::sort(times.begin(), times.end());
  times.insert(times.begin(), start);
  times.push_back(end);
  const double whole = end - start;
  const double bound = whole / 8;
  std::string stretches;  // every stretch above the bound
  for (size_t i = 1; i < times.size(); ++i) {
    const double s = times[i] - times[i - 1];
    if (s >= bound)
      stretches += " " + std::to_string(s) + " s after question " + std::to_string(i - 1) + ";";
  }
  EXPECT_TRUE(stretches.empty()) << "the decode took " << whole << " s of CPU, asked "
                                 << times.size() - 2 << " times, and ran without asking for"
                                 << stretches;
}

std::string ChainName(const ::testing::TestParamInfo<DecodeChain>& chain) {
  return chain.param == DecodeChain::kTracks ? "Tracks" : "Skeleton";
}

INSTANTIATE_TEST_SUITE_P(BothChains, DecoderCancellation,
                         ::testing::Values(DecodeChain::kTracks, DecodeChain::kSkeleton),
                         ChainName);

}  // namespace
}  // namespace bsls::decoder::test
