// The lump and cavities of thesis Tables 7.3-7.4, thesis-sized, pressed into
// the simulated face and measured through the whole chain: both sides
// rendered (noise sigma 3 grey levels), decoded, reconstructed with their
// calibrations from simulated sessions, joined, and measured against the
// exact ground truth of the simulator.
//
// Two references: a baseline scan of the same face without the lesions
// (registered onto the surface outside each region) and, for comparison, the
// single-scan cubic ring reference (docs/measurement.md says why the face's
// own shape limits it). And one yardstick for the decoder: the same frames
// reconstructed from a perfect decode (every lit and visible junction and
// line point of the simulator's truth), which shows what the rest of the
// chain can measure from these two views at all.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <numbers>
#include <optional>

#include "bsls/joining/join.h"
#include "bsls/measurement/lesion_measure.h"
#include "bsls/measurement/report.h"
#include "bsls/reconstruction/calibrated_model.h"
#include "bsls/reconstruction/reconstruction.h"
#include "bsls/reconstruction/side_pipeline.h"
#include "bsls/simulator/calibration_session.h"
#include "bsls/simulator/lesion.h"
#include "bsls/simulator/renderer.h"
#include "bsls/simulator/scene.h"
#include "bsls/testing/calibration_sessions.h"
#include "bsls/testing/surface_sampling.h"

namespace bsls::measurement {
namespace {

using calibration::testing::SessionKind;
using pattern::Side;

// Issue acceptance: height/depth within 0.5 mm, area within 3 % (volume: ours).
constexpr double kPeakToleranceMm = 0.5;
constexpr double kAreaRelativeTolerance = 0.03;
constexpr double kVolumeRelativeTolerance = 0.05;
constexpr double kNoiseSigma = 3.0;  // grey levels, as in the decoding tests

struct Lesion {
  const char* name;
  simulator::LesionParams params;  // rig (simulator world) frame
  // Share of the region the measured surface covers today, less a margin
  // of about a point for other machines' floating point (OpenCV's SIMD
  // paths differ in the last bits): a floor that keeps what the decoder
  // reaches; the whole region is lit and seen. The lump: 69.6 % since
  // surfaces are decoded by the track chain alone (2026-11-30, issue 25
  // part 1: one chain); 73.1 % while the skeleton chain's junctions and
  // lines were kept under the labels the track chain proved, 88.4 % before
  // that, when the skeleton chain's labels went unproven (the same chain put
  // wrong labels on the outside corpus's ramps and cavity,
  // docs/decoding.md). What is left out: the last rows of lines 9-13 on its
  // steep lower skirt, whose junctions the track chain sees but cannot prove.
  double min_coverage;
  // The region is covered enough for its measure without filling holes to
  // meet the acceptance both ways; else (the lump) only filling does, and
  // the unfilled area and volume can only fall short.
  bool whole = true;
};

// Thesis 7.2, Figures 7.12-7.13: a lump on the cheek near the mouth (Table
// 7.3: 15 mm, ~1474 mm^2), a cavity above the eyebrow (Table 7.4a: 15 mm,
// ~1240 mm^2) and one on the other cheek (Table 7.4b: 10 mm, ~412 mm^2).
const Lesion kLesions[] = {
    {"cheek lump",
     {.centre_xy_mm = {-42.0, -32.0}, .height_mm = 15.0, .radius_mm = 30.0, .top_radius_mm = 12.0},
     0.68,
     false},
    {"forehead cavity",
     {.centre_xy_mm = {-28.0, 50.0}, .height_mm = -15.0, .radius_mm = 28.0, .top_radius_mm = 11.0},
     0.99},
    {"cheek cavity",
     {.centre_xy_mm = {42.0, -30.0}, .height_mm = -10.0, .radius_mm = 16.0, .top_radius_mm = 7.0},
     0.99},
};

simulator::ThesisSceneOptions SceneOptions(bool with_lesions) {
  simulator::ThesisSceneOptions options;
  if (with_lesions)
    for (const Lesion& lesion : kLesions) options.face_lesions.push_back(lesion.params);
  return options;
}

// What a perfect decoder would report for `frame`: every lit and visible
// junction with its true label (q absolute: the slide row) and every true
// line centre.
decoder::DecodeResult PerfectDecode(const simulator::Frame& frame, Side side) {
  decoder::DecodeResult d;
  d.ok = true;
  d.side = side;
  d.width = frame.image.cols;
  d.height = frame.image.rows;
  d.q_absolute = true;
  for (const simulator::TruthJunction& j : frame.truth.junctions)
    if (j.visible) d.junctions.push_back({cv::Point2d(j.image.x(), j.image.y()), j.p, j.v, j.kind});
  std::sort(d.junctions.begin(), d.junctions.end(),
            [](const auto& a, const auto& b) { return a.p != b.p ? a.p < b.p : a.q < b.q; });
  for (const simulator::TruthLine& l : frame.truth.lines) {
    decoder::DecodedLine line{l.p, {}};
    for (const Eigen::Vector2d& q : l.points) line.points.emplace_back(q.x(), q.y());
    d.lines.push_back(std::move(line));
  }
  std::sort(d.lines.begin(), d.lines.end(), [](const auto& a, const auto& b) { return a.p < b.p; });
  return d;
}

// The joined face from the decoder, and from a perfect decode of the same
// frames; each with the default stitched strips and with thesis 5.2.1's row
// pairs (MeshParams::strips).
struct JoinedFaces {
  geometry::SurfaceMesh decoded, perfect, decoded_rows, perfect_rows;
};

// Both sides rendered, reconstructed with their calibrations and joined, in
// the calibration world frame; once per process and kind.
const JoinedFaces& Joined(bool with_lesions) {
  static std::map<bool, JoinedFaces> cache;
  if (auto it = cache.find(with_lesions); it != cache.end()) return it->second;
  const calibration::SideCalibration& left_cal =
      calibration::testing::SessionCalibration(SessionKind::kLeftNoisy);
  const calibration::SideCalibration& right_cal =
      calibration::testing::SessionCalibration(SessionKind::kRightClean);
  simulator::RenderParams render;
  render.noise_sigma = kNoiseSigma;
  render.seed = 5;
  reconstruction::ReconstructionParams row_pairs;
  row_pairs.mesh.strips = reconstruction::StripMethod::kRowPairs;
  std::optional<geometry::SurfaceMesh> sides[2], perfect[2], sides_rows[2], perfect_rows[2];
  for (Side side : {Side::kLeft, Side::kRight}) {
    const simulator::Frame frame = simulator::Render(
        simulator::ThesisScene(side, simulator::SurfaceKind::kFace, SceneOptions(with_lesions)),
        render);
    const calibration::SideCalibration& cal = side == Side::kLeft ? left_cal : right_cal;
    const reconstruction::SideOutcome out = reconstruction::ProcessSide(frame.image, side, &cal);
    EXPECT_TRUE(out.decode.ok) << out.decode.error;
    const int k = side == Side::kLeft ? 0 : 1;
    sides[k] = out.surface;
    const reconstruction::TriangulationModel model = reconstruction::ModelOfCalibration(cal);
    const decoder::DecodeResult truth = PerfectDecode(frame, side);
    perfect[k] = reconstruction::Reconstruct(truth, model);
    if (out.decode.ok) sides_rows[k] = reconstruction::Reconstruct(out.decode, model, row_pairs);
    perfect_rows[k] = reconstruction::Reconstruct(truth, model, row_pairs);
  }
  if (!sides[0] || !sides[1]) throw std::runtime_error("a side was not reconstructed");
  auto join = [](const auto& both) {
    return joining::JoinSharedFrame(*both[0], *both[1], {}).mesh;
  };
  return cache[with_lesions] = {join(sides), join(perfect), join(sides_rows), join(perfect_rows)};
}

const geometry::SurfaceMesh& JoinedFace(bool with_lesions) { return Joined(with_lesions).decoded; }

// The world frame of the calibrations: the rig frame moved to the target's origin.
Eigen::Vector2d ToCalibrationWorld(const Eigen::Vector2d& rig_xy) {
  const Eigen::Vector3d world =
      simulator::RigToCalibrationWorld(calibration::testing::SessionParams(SessionKind::kLeftNoisy),
                                       Eigen::Vector3d(rig_xy.x(), rig_xy.y(), 0.0));
  return world.head<2>();
}

struct Errors {
  double peak_mm, area_relative, volume_relative;
};

// Prints the figures of `m` for `lesion` and returns its errors against the truth.
Errors Compare(const char* how, const Lesion& lesion, const simulator::LesionTruth& truth,
               const LesionMeasurement& m) {
  std::printf(
      "[ figures  ] %s, %s: peak %.2f +- %.2f (true %.2f) mm, area %.1f +- %.1f (true %.1f) "
      "mm^2, volume %.0f +- %.0f (true %.0f) mm^3, reference residual %.3f mm\n",
      lesion.name, how, m.peak_mm.value, m.peak_mm.uncertainty, std::abs(truth.peak_mm),
      m.area_mm2.value, m.area_mm2.uncertainty, truth.area_on_base_mm2, m.volume_mm3.value,
      m.volume_mm3.uncertainty, std::abs(truth.volume_mm3), m.reference.residual_rms_mm);
  EXPECT_EQ(m.cavity, lesion.params.height_mm < 0.0) << lesion.name;
  return {m.peak_mm.value - std::abs(truth.peak_mm),
          m.area_mm2.value / truth.area_on_base_mm2 - 1.0,
          m.volume_mm3.value / std::abs(truth.volume_mm3) - 1.0};
}

class LesionChain : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    simulator::FaceModelParams face;
    face.obj_path = simulator::DefaultDataDir() / "canonical_face_model.obj";
    std::vector<simulator::LesionParams> params;
    for (const Lesion& lesion : kLesions) params.push_back(lesion.params);
    truth_surface_ = new simulator::LesionSurface(
        std::make_shared<simulator::MeshSurface>(simulator::LoadFaceMesh(face), "face"), params);
  }
  static void TearDownTestSuite() {
    delete truth_surface_;
    truth_surface_ = nullptr;
  }
  static simulator::LesionTruth Truth(std::size_t index) {
    return truth_surface_->Truth(index, LesionMeasureParams{}.level_fraction);
  }
  static Polygon2d Region(const Lesion& lesion) {
    return testing::Circle(ToCalibrationWorld(lesion.params.centre_xy_mm),
                           lesion.params.radius_mm + 2.0);
  }
  static inline simulator::LesionSurface* truth_surface_ = nullptr;
};

// Every lesion against the baseline scan (the acceptance), the same
// with the baseline repositioned (3 mm, 2 degrees: registration finds the
// motion, the figures stay), and against the single-scan cubic ring for
// comparison (reported, loose bounds: the face's own shape under a
// thesis-sized lesion is what a ring cannot know). One test: the chain's
// calibrations and renders are made once.
TEST_F(LesionChain, ThesisLesionsMeasuredThroughTheWholeChain) {
  const SurfaceQuery surface(JoinedFace(true));
  const geometry::SurfaceMesh& baseline = JoinedFace(false);
  geometry::SurfaceMesh moved = baseline;
  const Eigen::Isometry3d motion = Eigen::Translation3d(2.0, -1.5, 2.0) *
                                   Eigen::AngleAxisd(2.0 * std::numbers::pi / 180.0,
                                                     Eigen::Vector3d(0.3, 1.0, 0.2).normalized());
  for (Eigen::Vector3d& p : moved.positions) p = motion * p;
  for (Eigen::Vector3d& n : moved.normals) n = motion.linear() * n;

  std::optional<LesionMeasurement> lump;  // kLesions[0], for the perfect decode below
  for (std::size_t i = 0; i < std::size(kLesions); ++i) {
    const Lesion& lesion = kLesions[i];
    SCOPED_TRACE(lesion.name);
    const simulator::LesionTruth truth = Truth(i);
    const LesionMeasurement m = MeasureLesionAgainstBaseline(surface, baseline, Region(lesion));
    ASSERT_TRUE(m.baseline.has_value());
    if (i == 0) lump = m;
    std::printf(
        "[ figures  ] %s: surface covers %.1f %% of the region; registration %d steps, %d pairs, "
        "RMS %.3f mm, moved %.3f mm\n",
        lesion.name, 100.0 * m.surface_coverage, m.baseline->iterations, m.baseline->pairs,
        m.baseline->rms_mm, m.baseline->transform.translation().norm());
    const Errors e = Compare("baseline", lesion, truth, m);
    std::printf(
        "[ figures  ] %s, holes filled (%.1f %% of the region): area %.1f +- %.1f mm^2 (%+.1f "
        "%%), volume %.0f +- %.0f mm^3 (%+.1f %%)\n",
        lesion.name, 100.0 * m.filled_share, m.filled_area_mm2.value, m.filled_area_mm2.uncertainty,
        100.0 * (m.filled_area_mm2.value / truth.area_on_base_mm2 - 1.0), m.filled_volume_mm3.value,
        m.filled_volume_mm3.uncertainty,
        100.0 * (m.filled_volume_mm3.value / std::abs(truth.volume_mm3) - 1.0));
    EXPECT_LT(std::abs(e.peak_mm), kPeakToleranceMm);
    // The peak window centred on the lesion's top: within 0.07 mm here
    // (+0.11 to +0.25 mm centred on the extreme vertex, whose stripe has
    // the largest error of its own).
    EXPECT_LT(std::abs(e.peak_mm), 0.15);
    // Area and volume within the acceptance both ways (docs/measurement.md:
    // areas +1.5, -0.6 and -2.0 %).
    EXPECT_LT(e.area_relative, kAreaRelativeTolerance);
    EXPECT_LT(e.volume_relative, kVolumeRelativeTolerance);
    if (lesion.whole) {
      EXPECT_GT(e.area_relative, -kAreaRelativeTolerance);
      EXPECT_GT(e.volume_relative, -kVolumeRelativeTolerance);
    }
    EXPECT_GE(m.surface_coverage, lesion.min_coverage);
    // With the region's holes filled (LesionMeasurement::filled_*; the
    // lump: 12.5 % of its region, where line 4 passes behind the nasolabial
    // fold and on its lower outer skirt, where lines 10-13 end; flagged as
    // interpolated): the acceptance both ways for every lesion (lump area
    // +1.5 %, volume +0.1 %). Filling only adds area.
    const double filled_area = m.filled_area_mm2.value / truth.area_on_base_mm2 - 1.0;
    const double filled_volume = m.filled_volume_mm3.value / std::abs(truth.volume_mm3) - 1.0;
    EXPECT_GE(filled_area, e.area_relative);
    EXPECT_LT(std::abs(filled_area), kAreaRelativeTolerance);
    EXPECT_LT(std::abs(filled_volume), kVolumeRelativeTolerance);
    EXPECT_LT(m.baseline->transform.translation().norm(), 0.2);  // one rig, one pose

    const LesionMeasurement r = MeasureLesionAgainstBaseline(surface, moved, Region(lesion));
    const Eigen::Isometry3d residual = r.baseline->transform.inverse() * motion;
    std::printf("[ figures  ] %s, repositioned baseline: registration off by %.3f mm, %.4f deg\n",
                lesion.name, residual.translation().norm(),
                Eigen::AngleAxisd(residual.linear()).angle() * 180.0 / std::numbers::pi);
    EXPECT_LT(residual.translation().norm(), 0.1);
    EXPECT_LT(Eigen::AngleAxisd(residual.linear()).angle() * 180.0 / std::numbers::pi, 0.1);
    EXPECT_NEAR(r.peak_mm.value, m.peak_mm.value, 0.1);
    EXPECT_NEAR(r.area_mm2.value, m.area_mm2.value, 0.02 * m.area_mm2.value);

    // The ring cannot know the face's own shape under the lesion (the brow
    // under the forehead cavity); its reported sigma includes the ring's
    // misfit and covers the error.
    const LesionMeasurement ring_m = MeasureLesion(surface, Region(lesion));
    const Errors ring = Compare("cubic ring", lesion, truth, ring_m);
    EXPECT_LT(std::abs(ring.peak_mm), 2.5 * ring_m.peak_mm.uncertainty);
  }
  // The lump through a perfect decode of the same frames: what any decoder
  // could give the rest of the chain (its baseline scan decoded perfectly
  // too). Its surface covers 93.6 % of the region; the decoder's (69.6 %)
  // loses the last rows of lines 9-13 on the lower outer skirt, which lean
  // 60-75 degrees there (docs/measurement.md) and whose labels the track
  // chain does not prove (Lesion::min_coverage), and is held within 25
  // points of it.
  double default_coverage[2] = {0.0, 0.0};  // the lump's: decoder, perfect decode
  {
    const SurfaceQuery perfect(Joined(true).perfect);
    ASSERT_TRUE(lump.has_value());
    const LesionMeasurement best =
        MeasureLesionAgainstBaseline(perfect, Joined(false).perfect, Region(kLesions[0]));
    std::printf("[ figures  ] %s, perfect decode: surface covers %.1f %% of the region\n",
                kLesions[0].name, 100.0 * best.surface_coverage);
    const Errors e = Compare("perfect decode", kLesions[0], Truth(0), best);
    EXPECT_LT(std::abs(e.area_relative), kAreaRelativeTolerance);
    EXPECT_LT(std::abs(e.volume_relative), kVolumeRelativeTolerance);
    EXPECT_LE(lump->surface_coverage, best.surface_coverage + 0.01);
    EXPECT_GE(lump->surface_coverage, best.surface_coverage - 0.25);
    default_coverage[0] = lump->surface_coverage;
    default_coverage[1] = best.surface_coverage;
  }

  // The same frames with thesis 5.2.1's row pairs instead of stitched strips
  // (docs/reconstruction.md, "Stitched strips"): the same samples, so the
  // cavities measure the same (the level cut follows the stripes, not the
  // triangles); the lump's strips end where the shorter of their lines ends
  // on its lower outer skirt, where lines 10-13 lean 60-75 degrees and end
  // at different rows, so its surface covers less of the region and its area
  // is held one way only.
  for (const bool perfect_decode : {false, true}) {
    const JoinedFaces& with = Joined(true);
    const JoinedFaces& without = Joined(false);
    const SurfaceQuery rows(perfect_decode ? with.perfect_rows : with.decoded_rows);
    const geometry::SurfaceMesh& rows_baseline =
        perfect_decode ? without.perfect_rows : without.decoded_rows;
    for (std::size_t i = 0; i < std::size(kLesions); ++i) {
      SCOPED_TRACE(kLesions[i].name);
      const LesionMeasurement r =
          MeasureLesionAgainstBaseline(rows, rows_baseline, Region(kLesions[i]));
      std::printf("[ figures  ] %s, row pairs%s: surface covers %.1f %% of the region\n",
                  kLesions[i].name, perfect_decode ? ", perfect decode" : "",
                  100.0 * r.surface_coverage);
      const Errors e = Compare(perfect_decode ? "row pairs, perfect decode" : "row pairs",
                               kLesions[i], Truth(i), r);
      EXPECT_LT(std::abs(e.peak_mm), kPeakToleranceMm);
      EXPECT_LT(e.area_relative, kAreaRelativeTolerance);
      EXPECT_LT(e.volume_relative, kVolumeRelativeTolerance);
      if (i == 0) {
        EXPECT_LE(r.surface_coverage, default_coverage[perfect_decode ? 1 : 0] - 0.04);
      } else {
        EXPECT_GT(e.area_relative, -kAreaRelativeTolerance);
        EXPECT_GT(e.volume_relative, -kVolumeRelativeTolerance);
      }
    }
  }

  // Without registration the repositioned baseline is the wrong reference;
  // a baseline of something else (40 mm away) is refused.
  BaselineParams same_frame;
  same_frame.register_rigidly = false;
  const LesionMeasurement unregistered =
      MeasureLesionAgainstBaseline(surface, moved, Region(kLesions[0]), {}, same_frame);
  const LesionMeasurement registered =
      MeasureLesionAgainstBaseline(surface, moved, Region(kLesions[0]));
  EXPECT_GT(unregistered.reference.residual_rms_mm, 5.0 * registered.reference.residual_rms_mm);
  geometry::SurfaceMesh far = baseline;
  for (Eigen::Vector3d& p : far.positions) p.z() += 40.0;
  EXPECT_THROW(MeasureLesionAgainstBaseline(surface, far, Region(kLesions[0])), MeasurementError);
}

}  // namespace
}  // namespace bsls::measurement
