// The decoder's second thread: the sub-pixel centres measured ahead on it
// while the frame is interpreted (DecodeParams::measure_ahead) change
// nothing: the same junctions, labels and centres to the last bit as
// measured afterwards. A program of its own, registered RUN_SERIAL: beside
// other tests on two cores the second thread gets too little of a core to
// show that it measures ahead at all (one full `ctest -j2` run failed so).
#include <gtest/gtest.h>

#include <opencv2/core/utility.hpp>
#include <string>

#include "bsls/decoder/decoder.h"
#include "decoder_evaluation.h"

namespace bsls::decoder::test {
namespace {

TEST(Decoder, CentresMeasuredAheadGiveTheSameResult) {
  const int threads = cv::getNumThreads();
  cv::setNumThreads(2);  // a second thread even on a machine of one core
  for (const Side side : {Side::kLeft, Side::kRight}) {
    SCOPED_TRACE(std::string(pattern::ToString(side)));
    const simulator::Frame frame = RenderFrame(SurfaceKind::kFace, side, 2);
    // Measuring ahead is the skeleton chain's.
    const DecodeParams ahead_params = SkeletonChainParams();
    DecodeParams after_params = ahead_params;
    after_params.measure_ahead = false;
    const DecodeResult after = Decode(frame.image, side, after_params);
    ASSERT_TRUE(after.ok);
    EXPECT_EQ(after.centres_measured_ahead, 0);
    // How far the second thread gets before the interpretation ends is the
    // scheduler's (this program runs alone: RUN_SERIAL). Every decode must
    // give the same result; one of at most ten must have measured most of
    // them ahead (the left face of seed 1: 2263 rows and 3325 columns planned).
    DecodeResult ahead;
    for (int attempt = 0; attempt < 10; ++attempt) {
      SCOPED_TRACE("attempt " + std::to_string(attempt));
      ahead = Decode(frame.image, side, ahead_params);
      ASSERT_TRUE(ahead.ok);
      ASSERT_NO_FATAL_FAILURE(ExpectSameJunctions(ahead, after));
      ASSERT_EQ(ahead.lines.size(), after.lines.size());
      for (size_t i = 0; i < ahead.lines.size(); ++i) {
        EXPECT_EQ(ahead.lines[i].p, after.lines[i].p);
        EXPECT_EQ(ahead.lines[i].points, after.lines[i].points);
      }
      if (ahead.centres_measured_ahead > 1000) break;
    }
    EXPECT_GT(ahead.centres_measured_ahead, 1000);
  }
  cv::setNumThreads(threads);
}

}  // namespace
}  // namespace bsls::decoder::test
