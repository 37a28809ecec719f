// The lesion measurement (thesis 7.2, bsls::measurement) on a reconstructed
// simulated 512 x 512 left face with the thesis's cheek lump (Table 7.3:
// 15 mm high, 30 mm base radius) pressed in, against the reconstruction
// (triangulate + bridge + mesh, bsls::reconstruction::Reconstruct) of the
// same decoded frame measured in the same run: what an analyst's question
// costs next to making the surface it asks about.
//
// BM_MeasureLumpAgainstBaseline: MeasureLesionAgainstBaseline with a scan
// of the same face without the lump (registration, deviation, peak, area,
// volume, the holes filled). BM_MeasureLumpRing: MeasureLesion against the
// single-scan cubic ring reference. BM_SurfaceQuery: indexing the surface
// (SurfaceQuery), which every measurement call starts from.
// BM_MeasureLumpAgainstDamagedBaseline: as the first, with one vertex of the
// baseline thrown 1e8 mm away (a damaged upload the service must still
// answer quickly): its ratio should stay beside the first's.
// Counters: median_ms, reconstruct_ms (median Reconstruct of the frame),
// ratio = median / reconstruct_ms, and the measurement's filled_share and
// area_mm2 (so a change of the figures shows beside a change of speed).
//
// The model is the true camera and the light planes of the true projector,
// as a calibration would give them; the world frame is the rig's.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <numbers>
#include <vector>

#include "bsls/decoder/decoder.h"
#include "bsls/measurement/lesion_measure.h"
#include "bsls/measurement/surface_query.h"
#include "bsls/reconstruction/calibrated_model.h"
#include "bsls/reconstruction/reconstruction.h"
#include "bsls/simulator/renderer.h"
#include "bsls/simulator/scene.h"

namespace {

using Clock = std::chrono::steady_clock;
using bsls::pattern::Side;

const bsls::simulator::LesionParams kLump{
    .centre_xy_mm = {-42.0, -32.0}, .height_mm = 15.0, .radius_mm = 30.0, .top_radius_mm = 12.0};

double Median(std::vector<double> v) {
  std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
  return v[v.size() / 2];
}

double Ms(Clock::time_point since) {
  return std::chrono::duration<double, std::milli>(Clock::now() - since).count();
}

struct Side3d {
  bsls::decoder::DecodeResult decode;
  bsls::reconstruction::TriangulationModel model;
  bsls::geometry::SurfaceMesh mesh;
};

// The left face, with or without the lump, decoded and reconstructed once.
const Side3d& Face(bool with_lump) {
  static const auto make = [](bool lump) {
    bsls::simulator::ThesisSceneOptions options;
    if (lump) options.face_lesions.push_back(kLump);
    const bsls::simulator::Scene scene =
        bsls::simulator::ThesisScene(Side::kLeft, bsls::simulator::SurfaceKind::kFace, options);
    bsls::simulator::RenderParams params;
    params.noise_sigma = 3.0;
    Side3d out;
    out.decode = bsls::decoder::Decode(bsls::simulator::Render(scene, params).image, Side::kLeft);
    out.model =
        bsls::reconstruction::ModelOfKnownDevices(scene.side, scene.camera, scene.projector);
    if (out.decode.ok) out.mesh = bsls::reconstruction::Reconstruct(out.decode, out.model);
    return out;
  };
  static const Side3d lump = make(true);
  static const Side3d plain = make(false);
  return with_lump ? lump : plain;
}

// The region drawn around the lump: its base circle and 2 mm more.
bsls::measurement::Polygon2d Region() {
  bsls::measurement::Polygon2d region;
  for (int i = 0; i < 64; ++i) {
    const double a = 2.0 * std::numbers::pi * i / 64;
    region.push_back(kLump.centre_xy_mm +
                     (kLump.radius_mm + 2.0) * Eigen::Vector2d(std::cos(a), std::sin(a)));
  }
  return region;
}

// The baseline of this run: the reconstruction of the lump frame.
double ReconstructMs() {
  const Side3d& face = Face(true);
  std::vector<double> ms;
  for (int i = 0; i < 30; ++i) {
    const auto t = Clock::now();
    benchmark::DoNotOptimize(
        bsls::reconstruction::Reconstruct(face.decode, face.model).positions.data());
    ms.push_back(Ms(t));
  }
  return Median(ms);
}

// Times `measure` per iteration and sets the counters against the baseline.
template <typename Measure>
void Run(benchmark::State& state, Measure measure) {
  if (!Face(true).decode.ok || !Face(false).decode.ok) {
    state.SkipWithError("the face frames did not decode");
    return;
  }
  const double baseline = ReconstructMs();
  std::vector<double> ms;
  for (auto _ : state) {
    const auto t = Clock::now();
    measure();
    ms.push_back(Ms(t));
  }
  const double median = Median(ms);
  state.counters["median_ms"] = median;
  state.counters["reconstruct_ms"] = baseline;
  state.counters["ratio"] = median / baseline;
}

void BM_MeasureLumpAgainstBaseline(benchmark::State& state) {
  bsls::measurement::LesionMeasurement m;
  Run(state, [&] {
    const bsls::measurement::SurfaceQuery surface(Face(true).mesh);
    m = bsls::measurement::MeasureLesionAgainstBaseline(surface, Face(false).mesh, Region());
  });
  state.counters["area_mm2"] = m.area_mm2.value;
  state.counters["filled_share"] = m.filled_share;
}

void BM_MeasureLumpAgainstDamagedBaseline(benchmark::State& state) {
  bsls::geometry::SurfaceMesh damaged = Face(false).mesh;
  if (!damaged.positions.empty()) damaged.positions[damaged.positions.size() / 2].x() = 1e8;
  bsls::measurement::LesionMeasurement m;
  Run(state, [&] {
    const bsls::measurement::SurfaceQuery surface(Face(true).mesh);
    m = bsls::measurement::MeasureLesionAgainstBaseline(surface, damaged, Region());
  });
  state.counters["area_mm2"] = m.area_mm2.value;
  state.counters["filled_share"] = m.filled_share;
}

void BM_MeasureLumpRing(benchmark::State& state) {
  bsls::measurement::LesionMeasurement m;
  Run(state, [&] {
    const bsls::measurement::SurfaceQuery surface(Face(true).mesh);
    m = bsls::measurement::MeasureLesion(surface, Region());
  });
  state.counters["area_mm2"] = m.area_mm2.value;
  state.counters["filled_share"] = m.filled_share;
}

void BM_SurfaceQuery(benchmark::State& state) {
  Run(state, [] {
    const bsls::measurement::SurfaceQuery surface(Face(true).mesh);
    benchmark::DoNotOptimize(&surface);
  });
}

}  // namespace

BENCHMARK(BM_MeasureLumpAgainstBaseline)->Unit(benchmark::kMillisecond)->MinTime(2.0);
BENCHMARK(BM_MeasureLumpAgainstDamagedBaseline)->Unit(benchmark::kMillisecond)->MinTime(2.0);
BENCHMARK(BM_MeasureLumpRing)->Unit(benchmark::kMillisecond)->MinTime(2.0);
BENCHMARK(BM_SurfaceQuery)->Unit(benchmark::kMillisecond)->MinTime(1.0);

BENCHMARK_MAIN();
