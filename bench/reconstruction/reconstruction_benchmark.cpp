// Reconstruction (triangulate + bridge + mesh, bsls::reconstruction::Reconstruct)
// of one decoded simulated 512 x 512 left face, against the decode of the
// same frame measured in the same run. Counters: median_ms of Reconstruct,
// decode_ms (median decode, OpenCV's default threads), ratio = median
// reconstruct / median decode, vertices, triangles, bridged.
//
// The model is the true camera and the light planes of the true projector
// (the simulator's rig), as a calibration would give them.
//
// BM_FullBothSides: the whole reconstruction of a face as `bsls reconstruct`
// and the processing service run it (bsls::session) after the frames are in
// memory: decode both 512 x 512 sides, triangulate and mesh each (the two
// sides side by side, session::RunBothSides), join them in their shared frame
// (stitch along line 0, seam error). Counters: median_ms of the whole,
// decode_ms (median of decoding both sides alone the same way, same run),
// ratio = whole / decode alone, serial_decode_ms (the two decodes one after
// the other) and goal_ratio = whole / 40 ms (the goal: one camera
// frame period).
#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <vector>

#include "bsls/decoder/decoder.h"
#include "bsls/joining/join.h"
#include "bsls/reconstruction/calibrated_model.h"
#include "bsls/reconstruction/reconstruction.h"
#include "bsls/session/both_sides.h"
#include "bsls/simulator/renderer.h"
#include "bsls/simulator/scene.h"

namespace {

using Clock = std::chrono::steady_clock;

const bsls::simulator::Scene& FaceScene(bsls::pattern::Side side = bsls::pattern::Side::kLeft) {
  static const auto make = [](bsls::pattern::Side s) {
    bsls::simulator::ThesisSceneOptions options;
    options.face.obj_path = std::filesystem::path(BSLS_BENCH_DATA_DIR) / "canonical_face_model.obj";
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

void BM_FullBothSides(benchmark::State& state) {
  using bsls::pattern::Side;
  const cv::Mat& left = FaceFrame(Side::kLeft);
  const cv::Mat& right = FaceFrame(Side::kRight);
  const bsls::reconstruction::TriangulationModel left_model = TrueModel(FaceScene(Side::kLeft));
  const bsls::reconstruction::TriangulationModel right_model = TrueModel(FaceScene(Side::kRight));
  // The baselines: decoding both sides alone, side by side as the session
  // runs them and one after the other, in this run.
  // Side by side, each decode has a core of its own (as in the session).
  bsls::decoder::DecodeParams side_by_side;
  side_by_side.measure_ahead = false;
  std::vector<double> decode_ms, serial_decode_ms;
  for (int i = 0; i < 20; ++i) {
    auto t = Clock::now();
    const auto decoded = bsls::session::RunBothSides(
        [&] { return bsls::decoder::Decode(left, Side::kLeft, side_by_side); },
        [&] { return bsls::decoder::Decode(right, Side::kRight, side_by_side); });
    decode_ms.push_back(Ms(t));
    benchmark::DoNotOptimize(decoded.first.ok && decoded.second.ok);
    t = Clock::now();
    benchmark::DoNotOptimize(bsls::decoder::Decode(left, Side::kLeft).ok);
    benchmark::DoNotOptimize(bsls::decoder::Decode(right, Side::kRight).ok);
    serial_decode_ms.push_back(Ms(t));
  }
  // One side: decoded, then triangulated and meshed (an empty mesh when the
  // frame does not decode).
  auto side = [&](const cv::Mat& frame, Side s, const bsls::reconstruction::TriangulationModel& m) {
    const bsls::decoder::DecodeResult d = bsls::decoder::Decode(frame, s, side_by_side);
    return d.ok ? bsls::reconstruction::Reconstruct(d, m) : bsls::geometry::SurfaceMesh{};
  };
  std::vector<double> ms, join_ms;
  bsls::joining::JoinResult joined;
  for (auto _ : state) {
    const auto t = Clock::now();
    const auto [left_mesh, right_mesh] =
        bsls::session::RunBothSides([&] { return side(left, Side::kLeft, left_model); },
                                    [&] { return side(right, Side::kRight, right_model); });
    if (left_mesh.VertexCount() == 0 || right_mesh.VertexCount() == 0) {
      state.SkipWithError("decode failed");
      return;
    }
    const auto t_join = Clock::now();
    joined = bsls::joining::JoinSharedFrame(left_mesh, right_mesh, {});
    join_ms.push_back(Ms(t_join));
    ms.push_back(Ms(t));
    benchmark::DoNotOptimize(joined.mesh.positions.data());
  }
  const double median = Median(ms), baseline = Median(decode_ms);
  state.counters["serial_decode_ms"] = Median(serial_decode_ms);
  state.counters["join_ms"] = Median(join_ms);
  state.counters["median_ms"] = median;
  state.counters["decode_ms"] = baseline;
  state.counters["ratio"] = median / baseline;
  state.counters["goal_ratio"] = median / 40.0;
  state.counters["vertices"] = static_cast<double>(joined.mesh.VertexCount());
  state.counters["seam_rms_mm"] = joined.seam.rms_mm;
}

}  // namespace

BENCHMARK(BM_Reconstruct)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond)->MinTime(2.0);
BENCHMARK(BM_FullBothSides)->Unit(benchmark::kMillisecond)->MinTime(3.0);

BENCHMARK_MAIN();
