// The decoder with the thesis's feature extraction (Gaussian, Canny with the
// two-peak threshold, line-following thinning, pruning windows: thesis
// chapter 4) against the modern chain (Hessian stripe mask, Zhang-Suen,
// spur pruning), on simulated frames with ground truth. Counters: recall of
// lit and visible junctions, wrong labels, line-centre RMS error (px) and the
// median decode time (ms). Figures go to docs/decoding.md.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <map>
#include <vector>

#include "bsls/decoder/decoder.h"
#include "bsls/simulator/evaluation.h"
#include "bsls/simulator/renderer.h"
#include "bsls/simulator/scene.h"

namespace {

using bsls::extraction::ExtractionMethod;
using bsls::pattern::Side;
using bsls::simulator::SurfaceKind;

const bsls::simulator::Frame& Frame(SurfaceKind kind) {
  static std::map<SurfaceKind, bsls::simulator::Frame> frames;
  auto it = frames.find(kind);
  if (it != frames.end()) return it->second;
  bsls::simulator::ThesisSceneOptions options;
  bsls::simulator::RenderParams params;
  params.noise_sigma = 3.0;
  return frames[kind] = bsls::simulator::Render(
             bsls::simulator::ThesisScene(Side::kLeft, kind, options), params);
}

void BM_Method(benchmark::State& state) {
  const auto method = static_cast<ExtractionMethod>(state.range(0));
  const auto kind = static_cast<SurfaceKind>(state.range(1));
  const bsls::simulator::Frame& frame = Frame(kind);
  bsls::decoder::DecodeParams params;
  params.extraction.method = method;
  std::vector<double> ms;
  bsls::decoder::DecodeResult r;
  for (auto _ : state) {
    const auto t = std::chrono::steady_clock::now();
    r = bsls::decoder::Decode(frame.image, Side::kLeft, params);
    ms.push_back(
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t).count());
  }
  std::vector<bsls::simulator::PointLabel> decoded;
  for (const auto& j : r.junctions) decoded.push_back({j.p, j.q, j.position});
  const auto score =
      bsls::simulator::ScoreLabels(bsls::simulator::VisibleJunctions(frame.truth), decoded, 2.5);
  std::vector<bsls::simulator::LinePoints> decoded_lines;
  for (const auto& line : r.lines) decoded_lines.push_back({line.p, line.points});
  const auto lines =
      bsls::simulator::ScoreLines(bsls::simulator::TruthLines(frame.truth), decoded_lines);
  std::nth_element(ms.begin(), ms.begin() + ms.size() / 2, ms.end());
  state.counters["recall"] = score.Recall();
  state.counters["wrong"] = score.Wrong();
  state.counters["centre_rms_px"] = lines.rms;
  state.counters["median_ms"] = ms[ms.size() / 2];
  state.SetLabel(std::string(method == ExtractionMethod::kModern ? "modern " : "thesis ") +
                 std::string(bsls::simulator::ToString(kind)) +
                 (r.ok ? "" : " FAILED: " + r.error));
}

}  // namespace

BENCHMARK(BM_Method)
    ->ArgsProduct({{static_cast<int>(ExtractionMethod::kModern),
                    static_cast<int>(ExtractionMethod::kThesis)},
                   {static_cast<int>(SurfaceKind::kPlane), static_cast<int>(SurfaceKind::kBall),
                    static_cast<int>(SurfaceKind::kFace)}})
    ->Unit(benchmark::kMillisecond)
    ->Iterations(5);

BENCHMARK_MAIN();
