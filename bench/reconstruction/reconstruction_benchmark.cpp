// Reconstruction (triangulate + bridge + mesh, bsls::reconstruction::Reconstruct)
// of one decoded simulated 512 x 512 left face, against the decode of the
// same frame measured in the same run. Counters: median_ms of Reconstruct,
// decode_ms (median decode, OpenCV's default threads), ratio = median
// reconstruct / median decode, vertices, triangles, bridged.
//
// The model is the true camera and the light planes of the true projector
// (the simulator's rig), as a calibration would give them.
//
// BM_FullBothSides: the whole reconstruction of a face along the path
// `bsls reconstruct` runs once its files are read: session::ReconstructSession
// with the command's default choices (session::SessionParams{}: perspective
// light planes, stitched strips, no smoothing, join auto) on two calibrations
// made as `bsls calibrate` makes them (the simulator's thesis-rig sessions of
// both sides, written to a temporary folder and calibrated by
// calibration::CalibrateSide, once before the timing) and the two 512 x 512
// face frames in memory. That is: both sides decoded by the chain the session
// chooses for a surface, made absolute, triangulated and meshed side by side
// (session::RunBothSides), then joined. Left out: reading the PNGs and the
// calibration files, and writing the PLY and the report (the command's I/O).
// Counters: median_ms of the whole, decode_ms (median of decoding both sides
// alone with the session's decode parameters, side by side, same run),
// ratio = whole / decode alone, serial_decode_ms (the two decodes one after
// the other) and goal_ratio = whole / 10 ms (the goal: a quarter of one 40 ms camera frame).
#include <benchmark/benchmark.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <string>
#include <vector>

#include "bsls/calibration/manifest.h"
#include "bsls/calibration/side_calibration.h"
#include "bsls/decoder/decoder.h"
#include "bsls/joining/join.h"
#include "bsls/reconstruction/calibrated_model.h"
#include "bsls/reconstruction/reconstruction.h"
#include "bsls/session/both_sides.h"
#include "bsls/session/session.h"
#include "bsls/simulator/calibration_session.h"
#include "bsls/simulator/renderer.h"
#include "bsls/simulator/scene.h"

namespace {

using Clock = std::chrono::steady_clock;

const bsls::simulator::Scene& FaceScene(bsls::pattern::Side side = bsls::pattern::Side::kLeft) {
  static const auto make = [](bsls::pattern::Side s) {
    bsls::simulator::ThesisSceneOptions options;
    return bsls::simulator::ThesisScene(s, bsls::simulator::SurfaceKind::kFace, options);
  };
  static const bsls::simulator::Scene left = make(bsls::pattern::Side::kLeft);
  static const bsls::simulator::Scene right = make(bsls::pattern::Side::kRight);
  return side == bsls::pattern::Side::kLeft ? left : right;
}

const cv::Mat& FaceFrame(bsls::pattern::Side side = bsls::pattern::Side::kLeft) {
  static const auto render = [](bsls::pattern::Side s) {
    bsls::simulator::RenderParams params;
    params.noise_sigma = 3.0;
    return bsls::simulator::Renderer(FaceScene(s), params).RenderImage(1);
  };
  static const cv::Mat left = render(bsls::pattern::Side::kLeft);
  static const cv::Mat right = render(bsls::pattern::Side::kRight);
  return side == bsls::pattern::Side::kLeft ? left : right;
}

// The true model of a side's scene, as a calibration would give it.
bsls::reconstruction::TriangulationModel TrueModel(const bsls::simulator::Scene& scene) {
  return bsls::reconstruction::ModelOfKnownDevices(scene.side, scene.camera, scene.projector);
}

double Median(std::vector<double> v) {
  std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
  return v[v.size() / 2];
}

double Ms(Clock::time_point since) {
  return std::chrono::duration<double, std::milli>(Clock::now() - since).count();
}

void BM_Reconstruct(benchmark::State& state) {
  const cv::Mat& frame = FaceFrame();
  const bsls::simulator::Scene& scene = FaceScene();
  // The baseline: the decode of the same frame, in this run.
  std::vector<double> decode_ms;
  bsls::decoder::DecodeResult decode;
  for (int i = 0; i < 30; ++i) {
    const auto t = Clock::now();
    decode = bsls::decoder::Decode(frame, bsls::pattern::Side::kLeft);
    decode_ms.push_back(Ms(t));
  }
  if (!decode.ok) {
    state.SkipWithError(("decode failed: " + decode.error).c_str());
    return;
  }
  const bsls::reconstruction::TriangulationModel model = TrueModel(scene);
  // Argument 0: strips paired by row (thesis 5.2.1); 1: stitched (the default).
  bsls::reconstruction::ReconstructionParams params;
  params.mesh.strips = state.range(0) == 1 ? bsls::reconstruction::StripMethod::kStitched
                                           : bsls::reconstruction::StripMethod::kRowPairs;
  std::vector<double> ms;
  bsls::reconstruction::ReconstructionReport report;
  for (auto _ : state) {
    const auto t = Clock::now();
    const bsls::geometry::SurfaceMesh mesh =
        bsls::reconstruction::Reconstruct(decode, model, params, &report);
    ms.push_back(Ms(t));
    benchmark::DoNotOptimize(mesh.positions.data());
  }
  const double median = Median(ms), baseline = Median(decode_ms);
  state.counters["median_ms"] = median;
  state.counters["decode_ms"] = baseline;
  state.counters["ratio"] = median / baseline;
  state.counters["vertices"] = report.vertices;
  state.counters["triangles"] = report.triangles;
  state.counters["bridged"] = report.bridged_samples;
}

// One side's calibration as `bsls simulate-calibration` + `bsls calibrate`
// make it: the session rendered into a temporary folder and calibrated.
const bsls::calibration::SideCalibration& Calibration(bsls::pattern::Side side) {
  static const auto make = [](bsls::pattern::Side s) {
    namespace fs = std::filesystem;
    const fs::path folder = fs::temp_directory_path() /
                            ("bsls_bench_session_" + std::string(bsls::pattern::ToString(s)) + "_" +
                             std::to_string(::getpid()));
    bsls::simulator::WriteCalibrationSession(bsls::simulator::SimulateCalibrationSession(s, {}),
                                             folder);
    const bsls::calibration::SideCalibration c = bsls::calibration::CalibrateSide(
        bsls::calibration::LoadManifest(folder / bsls::simulator::kSessionManifestName));
    std::error_code ec;
    fs::remove_all(folder, ec);
    return c;
  };
  static const bsls::calibration::SideCalibration left = make(bsls::pattern::Side::kLeft);
  static const bsls::calibration::SideCalibration right = make(bsls::pattern::Side::kRight);
  return side == bsls::pattern::Side::kLeft ? left : right;
}

void BM_FullBothSides(benchmark::State& state) {
  using bsls::pattern::Side;
  const cv::Mat& left = FaceFrame(Side::kLeft);
  const cv::Mat& right = FaceFrame(Side::kRight);
  const bsls::calibration::SideCalibration& left_cal = Calibration(Side::kLeft);
  const bsls::calibration::SideCalibration& right_cal = Calibration(Side::kRight);
  const bsls::session::SessionParams params;  // `bsls reconstruct`'s defaults
  // The baselines: decoding both sides alone with the decode parameters the
  // session uses for a surface, side by side (as it runs them) and one after
  // the other, in this run.
  bsls::decoder::DecodeParams decode = params.side.decode;
  decode.chain = bsls::decoder::DecodeChain::kTracks;  // the session's, as ProcessSide sets it
  decode.chain = *bsls::decoder::ChainFor(params.side.chain, decode, nullptr);
  decode.measure_ahead = false;  // each side has a core of its own
  std::vector<double> decode_ms, serial_decode_ms;
  for (int i = 0; i < 20; ++i) {
    auto t = Clock::now();
    const auto decoded = bsls::session::RunBothSides(
        [&] { return bsls::decoder::Decode(left, Side::kLeft, decode); },
        [&] { return bsls::decoder::Decode(right, Side::kRight, decode); });
    decode_ms.push_back(Ms(t));
    benchmark::DoNotOptimize(decoded.first.ok && decoded.second.ok);
    t = Clock::now();
    benchmark::DoNotOptimize(bsls::decoder::Decode(left, Side::kLeft, decode).ok);
    benchmark::DoNotOptimize(bsls::decoder::Decode(right, Side::kRight, decode).ok);
    serial_decode_ms.push_back(Ms(t));
  }
  std::vector<double> ms;
  bsls::session::SessionOutcome outcome;
  for (auto _ : state) {
    const auto t = Clock::now();
    try {
      outcome = bsls::session::ReconstructSession(left, left_cal, right, right_cal, params);
    } catch (const std::exception& e) {
      state.SkipWithError(e.what());
      return;
    }
    ms.push_back(Ms(t));
    benchmark::DoNotOptimize(outcome.joined.mesh.positions.data());
  }
  const double median = Median(ms), baseline = Median(decode_ms);
  state.counters["serial_decode_ms"] = Median(serial_decode_ms);
  state.counters["median_ms"] = median;
  state.counters["decode_ms"] = baseline;
  state.counters["ratio"] = median / baseline;
  state.counters["goal_ratio"] = median / 10.0;
  state.counters["vertices"] = static_cast<double>(outcome.joined.mesh.VertexCount());
  state.counters["seam_rms_mm"] = outcome.joined.seam.rms_mm;
}

}  // namespace

BENCHMARK(BM_Reconstruct)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond)->MinTime(2.0);
BENCHMARK(BM_FullBothSides)->Unit(benchmark::kMillisecond)->MinTime(3.0);

BENCHMARK_MAIN();
