// Decode of one simulated face frame at 512x512 and 2048x2048, against a
// baseline measured in the same run on the same frame: cv::GaussianBlur
// (5x5, sigma 1) followed by cv::Canny. Counters: median_ms of the decode,
// baseline_ms, ratio = median decode / median baseline (goal at 512: <= 4),
// and the median time of each stage (extraction_ms, interpretation_ms,
// subpixel_ms, from DecodeResult::times).
//
// BM_Decode decodes with the default parameters (the track chain) and
// OpenCV's default thread count (the decoder's parallel stages use
// cv::parallel_for_); BM_DecodeSingleThread sets cv::setNumThreads(1) for
// both the baseline and the decode, so its ratio compares single-threaded
// code with single-threaded OpenCV. BM_DecodeSkeleton and
// BM_DecodeSkeletonSingleThread are the same for the skeleton chain
// (DecodeChain::kSkeleton), and BM_DecodeSkeletonNothingAhead the skeleton
// chain with DecodeParams::measure_ahead off: the sub-pixel centres measured
// after the interpretation instead of on the second thread during it
// (counter ahead: centres measured ahead).
#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <map>
#include <opencv2/imgproc.hpp>
#include <vector>

#include "bsls/decoder/decoder.h"
#include "bsls/extraction/stripe_pitch.h"
#include "bsls/simulator/renderer.h"
#include "bsls/simulator/scene.h"

namespace {

using Clock = std::chrono::steady_clock;

const cv::Mat& FaceFrame(int size) {
  static std::map<int, cv::Mat> frames;
  auto it = frames.find(size);
  if (it != frames.end()) return it->second;
  bsls::simulator::ThesisSceneOptions options;
  options.rig.width = size;
  options.rig.height = size;
  bsls::simulator::RenderParams params;
  params.supersampling = size > 1024 ? 1 : 3;
  params.noise_sigma = 3.0;
  const auto scene = bsls::simulator::ThesisScene(bsls::pattern::Side::kLeft,
                                                  bsls::simulator::SurfaceKind::kFace, options);
  return frames[size] = bsls::simulator::Renderer(scene, params).RenderImage(1);
}

double Median(std::vector<double> v) {
  std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
  return v[v.size() / 2];
}

double BaselineOnce(const cv::Mat& frame) {
  const auto t = Clock::now();
  cv::Mat blurred, edges;
  cv::GaussianBlur(frame, blurred, cv::Size(5, 5), 1.0);
  cv::Canny(blurred, edges, 30, 90);
  benchmark::DoNotOptimize(edges.data);
  return std::chrono::duration<double, std::milli>(Clock::now() - t).count();
}

void BM_GaussianBlurCanny(benchmark::State& state) {
  const cv::Mat& frame = FaceFrame(static_cast<int>(state.range(0)));
  std::vector<double> ms;
  for (auto _ : state) ms.push_back(BaselineOnce(frame));
  state.counters["median_ms"] = Median(ms);
}

// Decodes the face frame of side state.range(0) with `threads` OpenCV
// threads (0: leave OpenCV's default) and `params`, and reports the
// counters above.
void DecodeWithThreads(benchmark::State& state, int threads,
                       const bsls::decoder::DecodeParams& params = {}) {
  const cv::Mat& frame = FaceFrame(static_cast<int>(state.range(0)));
  const int default_threads = cv::getNumThreads();
  if (threads > 0) cv::setNumThreads(threads);
  // The baseline, measured in this run on this frame.
  std::vector<double> base;
  for (int i = 0; i < 30; ++i) base.push_back(BaselineOnce(frame));
  std::vector<double> ms, extraction, interpretation, subpixel;
  int junctions = 0, ahead = 0;
  for (auto _ : state) {
    const auto t = Clock::now();
    const bsls::decoder::DecodeResult r =
        bsls::decoder::Decode(frame, bsls::pattern::Side::kLeft, params);
    ms.push_back(std::chrono::duration<double, std::milli>(Clock::now() - t).count());
    extraction.push_back(r.times.extraction_ms);
    interpretation.push_back(r.times.interpretation_ms);
    subpixel.push_back(r.times.subpixel_ms);
    junctions = static_cast<int>(r.junctions.size());
    ahead = r.centres_measured_ahead;
    benchmark::DoNotOptimize(junctions);
  }
  cv::setNumThreads(default_threads);
  const double median = Median(ms), baseline = Median(base);
  state.counters["median_ms"] = median;
  state.counters["baseline_ms"] = baseline;
  state.counters["ratio"] = median / baseline;
  state.counters["extraction_ms"] = Median(extraction);
  state.counters["interpretation_ms"] = Median(interpretation);
  state.counters["subpixel_ms"] = Median(subpixel);
  state.counters["threads"] = threads > 0 ? threads : default_threads;
  state.counters["junctions"] = junctions;
  state.counters["ahead"] = ahead;
  state.counters["pixels"] = static_cast<double>(frame.total());
}

void BM_Decode(benchmark::State& state) { DecodeWithThreads(state, 0); }

// The stripe pitch alone (the decoder's first step), against the baseline.
void BM_MeasureStripePitch(benchmark::State& state) {
  const cv::Mat& frame = FaceFrame(static_cast<int>(state.range(0)));
  std::vector<double> base, ms;
  for (int i = 0; i < 30; ++i) base.push_back(BaselineOnce(frame));
  double pitch = 0.0;
  for (auto _ : state) {
    const auto t = Clock::now();
    pitch = bsls::extraction::MeasureStripePitch(frame).value_or(0.0);
    ms.push_back(std::chrono::duration<double, std::milli>(Clock::now() - t).count());
    benchmark::DoNotOptimize(pitch);
  }
  state.counters["median_ms"] = Median(ms);
  state.counters["baseline_ms"] = Median(base);
  state.counters["ratio"] = Median(ms) / Median(base);
  state.counters["pitch"] = pitch;
}

void BM_DecodeSingleThread(benchmark::State& state) { DecodeWithThreads(state, 1); }

// The skeleton chain: the same as BM_Decode and BM_DecodeSingleThread with
// DecodeChain::kSkeleton.
void BM_DecodeSkeleton(benchmark::State& state) {
  DecodeWithThreads(state, 0, bsls::decoder::SkeletonChainParams());
}

void BM_DecodeSkeletonSingleThread(benchmark::State& state) {
  DecodeWithThreads(state, 1, bsls::decoder::SkeletonChainParams());
}

void BM_DecodeSkeletonNothingAhead(benchmark::State& state) {
  bsls::decoder::DecodeParams params = bsls::decoder::SkeletonChainParams();
  params.measure_ahead = false;
  DecodeWithThreads(state, 0, params);
}

}  // namespace

BENCHMARK(BM_GaussianBlurCanny)->Arg(512)->Arg(2048)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_MeasureStripePitch)->Arg(512)->Arg(2048)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_Decode)->Arg(512)->Unit(benchmark::kMillisecond)->MinTime(2.0);
BENCHMARK(BM_Decode)->Arg(2048)->Unit(benchmark::kMillisecond)->Iterations(20);
BENCHMARK(BM_DecodeSingleThread)->Arg(512)->Unit(benchmark::kMillisecond)->MinTime(2.0);
BENCHMARK(BM_DecodeSingleThread)->Arg(2048)->Unit(benchmark::kMillisecond)->Iterations(20);
BENCHMARK(BM_DecodeSkeleton)->Arg(512)->Unit(benchmark::kMillisecond)->MinTime(2.0);
BENCHMARK(BM_DecodeSkeleton)->Arg(2048)->Unit(benchmark::kMillisecond)->Iterations(5);
BENCHMARK(BM_DecodeSkeletonNothingAhead)->Arg(512)->Unit(benchmark::kMillisecond)->MinTime(2.0);
BENCHMARK(BM_DecodeSkeletonSingleThread)->Arg(512)->Unit(benchmark::kMillisecond)->MinTime(2.0);
BENCHMARK(BM_DecodeSkeletonSingleThread)->Arg(2048)->Unit(benchmark::kMillisecond)->Iterations(5);

BENCHMARK_MAIN();
