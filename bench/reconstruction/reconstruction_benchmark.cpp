// Reconstruction (triangulate + bridge + mesh, bsls::reconstruction::Reconstruct)
// of one decoded simulated 512 x 512 left face, against the decode of the
// same frame measured in the same run. Counters: median_ms of Reconstruct,
// decode_ms (median decode, OpenCV's default threads), ratio = median
// reconstruct / median decode, vertices, triangles, bridged.
//
// The model is the true camera and the light planes of the true projector
// (the simulator's rig), as a calibration would give them.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <vector>

#include "bsls/decoder/decoder.h"
#include "bsls/reconstruction/reconstruction.h"
#include "bsls/simulator/renderer.h"
#include "bsls/simulator/scene.h"

namespace {

using Clock = std::chrono::steady_clock;

const bsls::simulator::Scene& FaceScene() {
  static const bsls::simulator::Scene scene = [] {
    bsls::simulator::ThesisSceneOptions options;
    options.face.obj_path = std::filesystem::path(BSLS_BENCH_DATA_DIR) / "canonical_face_model.obj";
    return bsls::simulator::ThesisScene(bsls::pattern::Side::kLeft,
                                        bsls::simulator::SurfaceKind::kFace, options);
  }();
  return scene;
}

const cv::Mat& FaceFrame() {
  static const cv::Mat frame = [] {
    bsls::simulator::RenderParams params;
    params.noise_sigma = 3.0;
    return bsls::simulator::Renderer(FaceScene(), params).RenderImage(1);
  }();
  return frame;
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
  bsls::reconstruction::TriangulationModel model;
  model.side = scene.side;
  model.geometry = bsls::reconstruction::CalibratedGeometry{
      scene.camera, bsls::reconstruction::LightPlanesOfProjector(scene.projector, scene.side),
      scene.projector};
  std::vector<double> ms;
  bsls::reconstruction::ReconstructionReport report;
  for (auto _ : state) {
    const auto t = Clock::now();
    const bsls::geometry::SurfaceMesh mesh =
        bsls::reconstruction::Reconstruct(decode, model, {}, &report);
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

}  // namespace

BENCHMARK(BM_Reconstruct)->Unit(benchmark::kMillisecond)->MinTime(2.0);

BENCHMARK_MAIN();
