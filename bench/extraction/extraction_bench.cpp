// Google Benchmark of every extraction kernel and stage at 512 x 512 and
// 2048 x 2048 on a synthetic brick frame (vertical lines every 13 px joined
// by staggered horizontal segments, blurred, with noise).
//
// Each benchmark also reports, as counters, the time of cv::GaussianBlur
// (sigma 1 px, 7 x 7, the default smoothing) on the same frame measured in
// the same run (gauss_ms) and its own time in units of it (x_gauss).
// OpenCV runs single-threaded here so that the ratios are stable.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <functional>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>
#include <vector>

#include "bsls/extraction/edge_detect.h"
#include "bsls/extraction/enhance.h"
#include "bsls/extraction/feature_extraction.h"
#include "bsls/extraction/pruning.h"
#include "bsls/extraction/stripe_centre.h"
#include "bsls/extraction/stripe_detect.h"
#include "bsls/extraction/thinning.h"

namespace bsls::extraction {
namespace {

constexpr int kPitch = 13;  // px between vertical lines and between segment rows

// The synthetic brick frame of side n: lines 2-4 px wide, segments 3 px,
// ground 25, stripes 140 grey levels, blur sigma 1, noise sigma 3 (seeded).
cv::Mat BrickFrame(int n) {
  cv::Mat f(n, n, CV_32F, cv::Scalar(25));
  for (int p = 0; p * kPitch + 8 < n; ++p) {
    const int x = 8 + p * kPitch;
    const int width = 2 + p % 3;
    cv::rectangle(f, cv::Rect(x - width / 2, 0, width, n), cv::Scalar(140), cv::FILLED);
    for (int v = p % 2; v * kPitch < n; v += 2)  // staggered: every other row per column
      cv::rectangle(f, cv::Rect(x, v * kPitch + 6, kPitch, 3), cv::Scalar(140), cv::FILLED);
  }
  cv::GaussianBlur(f, f, cv::Size(0, 0), 1.0);
  cv::Mat noise(f.size(), CV_32F);
  cv::RNG rng(12345);
  rng.fill(noise, cv::RNG::NORMAL, 0.0, 3.0);
  cv::Mat out;
  cv::Mat(f + noise).convertTo(out, CV_8U);
  return out;
}

double MillisecondsPerCall(const std::function<void()>& call, double budget_ms) {
  using Clock = std::chrono::steady_clock;
  call();  // warm up
  int calls = 0;
  const auto start = Clock::now();
  double elapsed = 0.0;
  do {
    call();
    ++calls;
    elapsed = std::chrono::duration<double, std::milli>(Clock::now() - start).count();
  } while (elapsed < budget_ms);
  return elapsed / calls;
}

// Runs `body` as the timed loop and adds the GaussianBlur reference counters.
void RunAgainstGaussian(benchmark::State& state, const cv::Mat& frame,
                        const std::function<void()>& body) {
  cv::Mat blurred;
  const double gauss_ms = MillisecondsPerCall(
      [&] {
        cv::GaussianBlur(frame, blurred, cv::Size(7, 7), 1.0, 1.0, cv::BORDER_REPLICATE);
        benchmark::DoNotOptimize(blurred.data);
      },
      50.0);
  using Clock = std::chrono::steady_clock;
  double total_ms = 0.0;
  for (auto _ : state) {
    const auto start = Clock::now();
    body();
    total_ms += std::chrono::duration<double, std::milli>(Clock::now() - start).count();
  }
  const double per_iteration = total_ms / static_cast<double>(state.iterations());
  state.counters["gauss_ms"] = gauss_ms;
  state.counters["x_gauss"] = per_iteration / gauss_ms;
  state.SetItemsProcessed(state.iterations());  // frames
}

// Inputs the later stages need, made once per benchmark (not timed).
struct Inputs {
  cv::Mat grey;
  cv::Mat mask;      // stripe mask (modern detector)
  cv::Mat thinned;   // Zhang-Suen skeleton of the mask
  cv::Mat skeleton;  // the same made strictly one pixel wide
};

Inputs MakeInputs(int n) {
  Inputs in;
  in.grey = BrickFrame(n);
  in.mask = DetectStripes(in.grey, {});
  in.thinned = ZhangSuenThin(in.mask);
  in.skeleton = MakeOnePixelWide(in.thinned);
  return in;
}

#define BSLS_FRAME_BENCHMARK(name, body_expr)                       \
  void name(benchmark::State& state) {                              \
    const Inputs in = MakeInputs(static_cast<int>(state.range(0))); \
    cv::Mat out;                                                    \
    RunAgainstGaussian(state, in.grey, [&] {                        \
      out = (body_expr);                                            \
      benchmark::DoNotOptimize(out.data);                           \
    });                                                             \
  }                                                                 \
  BENCHMARK(name)->Arg(512)->Arg(2048)->Unit(benchmark::kMillisecond)

// Reference.
BSLS_FRAME_BENCHMARK(BM_CvGaussianBlur, [&] {
  cv::Mat b;
  cv::GaussianBlur(in.grey, b, cv::Size(7, 7), 1.0, 1.0, cv::BORDER_REPLICATE);
  return b;
}());

// Thesis 4.1: enhancement.
BSLS_FRAME_BENCHMARK(BM_GaussianSmooth, GaussianSmooth(in.grey, 1.0));
BSLS_FRAME_BENCHMARK(BM_DaviesSmooth, DaviesSmooth(in.grey));
BSLS_FRAME_BENCHMARK(BM_IteratedBinomialSmooth2, IteratedBinomialSmooth(in.grey, 2));
BSLS_FRAME_BENCHMARK(BM_MedianSmooth3, MedianSmooth(in.grey, 3));
BSLS_FRAME_BENCHMARK(BM_AdaptiveContrast, AdaptiveContrast(in.grey, {}));
BSLS_FRAME_BENCHMARK(BM_HistogramEqualise, HistogramEqualise(in.grey));

// Thesis 4.2: edge detection.
BSLS_FRAME_BENCHMARK(BM_SobelMagnitude, SobelMagnitude(in.grey));
BSLS_FRAME_BENCHMARK(BM_LaplacianOfGaussian,
                     LaplacianOfGaussian(in.grey, 1.0, LaplacianMask::kH2EightNeighbour));
BSLS_FRAME_BENCHMARK(BM_CannyTwoPeak, CannyEdges(in.grey, {}));
BSLS_FRAME_BENCHMARK(BM_HysteresisThreshold, HysteresisThreshold(in.grey, 60, 100));

// Modern stripe detection.
BSLS_FRAME_BENCHMARK(BM_RidgeStrength, RidgeStrength(in.grey, {}));
BSLS_FRAME_BENCHMARK(BM_DetectStripesHessian, DetectStripes(in.grey, {}));
BSLS_FRAME_BENCHMARK(BM_DetectStripesAdaptive, [&] {
  StripeDetectParams p;
  p.method = StripeDetector::kAdaptiveThreshold;
  return DetectStripes(in.grey, p);
}());

// Thesis 4.3: thinning (of the modern mask).
BSLS_FRAME_BENCHMARK(BM_ZhangSuenThin, ZhangSuenThin(in.mask));
BSLS_FRAME_BENCHMARK(BM_LineFollowingThin, LineFollowingThin(in.mask, {}));
BSLS_FRAME_BENCHMARK(BM_MakeOnePixelWide, MakeOnePixelWide(in.thinned));
BSLS_FRAME_BENCHMARK(BM_RecentreOnRidge, RecentreOnRidge(in.skeleton, in.grey));

// Thesis 4.4: pruning.
BSLS_FRAME_BENCHMARK(BM_ApplyPruningWindows, ApplyPruningWindows(in.skeleton));
BSLS_FRAME_BENCHMARK(BM_PruneSpurs, PruneSpurs(in.skeleton));
BSLS_FRAME_BENCHMARK(BM_RemoveSmallComponents, RemoveSmallComponents(in.skeleton, 10));

// The chains.
BSLS_FRAME_BENCHMARK(BM_ExtractFeaturesModern, ExtractFeatures(in.grey).skeleton);
BSLS_FRAME_BENCHMARK(BM_ExtractFeaturesThesis, [&] {
  ExtractionParams p;
  p.method = ExtractionMethod::kThesis;
  return ExtractFeatures(in.grey, p).skeleton;
}());

// Sub-pixel centres: every vertical line in every row of the frame.
void BM_StripeCentresWholeFrame(benchmark::State& state) {
  const int n = static_cast<int>(state.range(0));
  const cv::Mat grey = BrickFrame(n);
  std::vector<int> lines;
  for (int p = 0; p * kPitch + 8 < n; ++p) lines.push_back(8 + p * kPitch);
  size_t found = 0;
  RunAgainstGaussian(state, grey, [&] {
    found = 0;
    for (int y = 0; y < n; ++y)
      for (int x : lines) found += StripeCentreInRow(grey, y, x).has_value();
    benchmark::DoNotOptimize(found);
  });
  state.counters["calls"] = static_cast<double>(lines.size()) * n;
  state.counters["found"] = static_cast<double>(found);
}
BENCHMARK(BM_StripeCentresWholeFrame)->Arg(512)->Arg(2048)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace bsls::extraction

int main(int argc, char** argv) {
  cv::setNumThreads(1);
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
