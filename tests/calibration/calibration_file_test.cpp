// The calibration file: round trip, atomic save, and a clear error for every
// kind of bad file.
#include "bsls/calibration/calibration_file.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "bsls/calibration/calibration_header.h"
#include "bsls/common/errors.h"
#include "bsls/testing/calibration_sessions.h"

namespace bsls::calibration {
namespace {

namespace fs = std::filesystem;
using testing::SessionKind;

constexpr double kRelative = 1e-12;  // round trip, relative to the value (absolute near 0)
constexpr const char* kVersion = "9.8.7-test";

void ExpectNear(double a, double b, const std::string& what) {
  EXPECT_LE(std::abs(a - b), kRelative * std::max({std::abs(a), std::abs(b), 1.0})) << what;
}

template <typename Derived>
void ExpectNear(const Eigen::MatrixBase<Derived>& a, const Eigen::MatrixBase<Derived>& b,
                const std::string& what) {
  ASSERT_EQ(a.size(), b.size()) << what;
  for (Eigen::Index i = 0; i < a.size(); ++i)
    ExpectNear(a.derived().data()[i], b.derived().data()[i], what + "[" + std::to_string(i) + "]");
}

void ExpectSameModel(const geometry::PinholeModel& a, const geometry::PinholeModel& b,
                     const std::string& what) {
  const auto &x = a.intrinsics(), &y = b.intrinsics();
  ExpectNear(x.fx, y.fx, what + ".fx");
  ExpectNear(x.fy, y.fy, what + ".fy");
  ExpectNear(x.cx, y.cx, what + ".cx");
  ExpectNear(x.cy, y.cy, what + ".cy");
  ExpectNear(x.k1, y.k1, what + ".k1");
  ExpectNear(x.k2, y.k2, what + ".k2");
  ExpectNear(a.pose().rotation, b.pose().rotation, what + ".rotation");
  ExpectNear(a.pose().translation, b.pose().translation, what + ".translation");
}

void ExpectSameStripeReport(const StripeFitReport& a, const StripeFitReport& b,
                            const std::string& what) {
  EXPECT_EQ(a.points_used, b.points_used) << what;
  EXPECT_EQ(a.points_dropped, b.points_dropped) << what;
  ExpectNear(a.rms_mm, b.rms_mm, what + ".rms_mm");
  ExpectNear(a.max_mm, b.max_mm, what + ".max_mm");
  ExpectNear(a.first_pass_rms_mm, b.first_pass_rms_mm, what + ".first_pass_rms_mm");
}

// Every stored field (calibration_file.h lists what is not stored).
void ExpectSameCalibration(const SideCalibration& a, const SideCalibration& b) {
  EXPECT_EQ(a.side, b.side);
  EXPECT_EQ(a.width, b.width);
  EXPECT_EQ(a.height, b.height);
  EXPECT_EQ(a.manifest_sha256, b.manifest_sha256);
  EXPECT_EQ(a.pattern.lines, b.pattern.lines);
  EXPECT_EQ(a.pattern.rows, b.pattern.rows);
  ExpectNear(a.pattern.stroke_width, b.pattern.stroke_width, "stroke_width");
  EXPECT_EQ(a.target.rows, b.target.rows);
  EXPECT_EQ(a.target.cols, b.target.cols);
  ExpectNear(a.target.pitch_mm, b.target.pitch_mm, "pitch_mm");
  ExpectNear(a.target.square_mm, b.target.square_mm, "square_mm");

  ExpectSameModel(a.camera.model, b.camera.model, "camera");
  const CameraCalibrationReport &ra = a.camera.report, &rb = b.camera.report;
  EXPECT_EQ(ra.num_points, rb.num_points);
  EXPECT_EQ(ra.num_views, rb.num_views);
  for (const auto& [x, y, name] :
       {std::tuple{ra.rms_px, rb.rms_px, "rms_px"},
        {ra.max_px, rb.max_px, "max_px"},
        {ra.rms_mm, rb.rms_mm, "rms_mm"},
        {ra.max_mm, rb.max_mm, "max_mm"},
        {ra.residual_sigma_px, rb.residual_sigma_px, "residual_sigma_px"},
        {ra.f_px, rb.f_px, "f_px"},
        {ra.sx, rb.sx, "sx"}})
    ExpectNear(x, y, std::string("camera.report.") + name);
  EXPECT_EQ(ra.initialisation, rb.initialisation);
  EXPECT_EQ(ra.iterations, rb.iterations);
  EXPECT_EQ(ra.converged, rb.converged);
  ASSERT_EQ(ra.view_rms_px.size(), rb.view_rms_px.size());
  for (size_t i = 0; i < ra.view_rms_px.size(); ++i) {
    ExpectNear(ra.view_rms_px[i], rb.view_rms_px[i], "view_rms_px");
    ExpectNear(ra.view_rms_mm[i], rb.view_rms_mm[i], "view_rms_mm");
  }
  ASSERT_EQ(ra.sigmas.has_value(), rb.sigmas.has_value());
  if (ra.sigmas) {
    ExpectNear(ra.sigmas->f_px, rb.sigmas->f_px, "sigmas.f_px");
    ExpectNear(ra.sigmas->k1, rb.sigmas->k1, "sigmas.k1");
    ExpectNear(ra.sigmas->k2, rb.sigmas->k2, "sigmas.k2");
    ExpectNear(ra.sigmas->cx_px, rb.sigmas->cx_px, "sigmas.cx_px");
    ExpectNear(ra.sigmas->rotation_rad, rb.sigmas->rotation_rad, "sigmas.rotation_rad");
    ExpectNear(ra.sigmas->translation_mm, rb.sigmas->translation_mm, "sigmas.translation_mm");
  }
  ASSERT_EQ(a.camera_views.size(), b.camera_views.size());
  for (size_t i = 0; i < a.camera_views.size(); ++i) {
    EXPECT_EQ(a.camera_views[i].image, b.camera_views[i].image);
    ExpectNear(a.camera_views[i].z_mm, b.camera_views[i].z_mm, "camera_views.z_mm");
    ExpectNear(a.camera_views[i].max_grid_residual, b.camera_views[i].max_grid_residual,
               "camera_views.max_grid_residual");
  }

  ExpectNear(a.parallel.model.normal, b.parallel.model.normal, "parallel.normal");
  ExpectNear(a.parallel.model.spacing_mm, b.parallel.model.spacing_mm, "parallel.spacing_mm");
  ExpectNear(a.parallel.model.e0, b.parallel.model.e0, "parallel.e0");
  ExpectSameStripeReport(a.parallel.report, b.parallel.report, "parallel");
  const PerspectivePlaneModel &pa = a.perspective.model, &pb = b.perspective.model;
  ExpectNear(pa.n0, pb.n0, "perspective.n0");
  ExpectNear(pa.p, pb.p, "perspective.p");
  ExpectNear(pa.centre_mm, pb.centre_mm, "perspective.centre_mm");
  ExpectNear(pa.axis_direction, pb.axis_direction, "perspective.axis_direction");
  EXPECT_EQ(pa.gauge_axis, pb.gauge_axis);
  EXPECT_EQ(pa.centre_axis, pb.centre_axis);
  ExpectNear(a.perspective.centre_to_origin_mm, b.perspective.centre_to_origin_mm, "centre_to_o");
  ExpectNear(a.perspective.axis_to_origin_mm, b.perspective.axis_to_origin_mm, "axis_to_o");
  ExpectSameStripeReport(a.perspective.report, b.perspective.report, "perspective");

  ASSERT_EQ(a.projector_matrix.has_value(), b.projector_matrix.has_value());
  if (a.projector_matrix) {
    ExpectSameModel(a.projector_matrix->model, b.projector_matrix->model, "projector");
    ExpectNear(a.projector_matrix->matrix, b.projector_matrix->matrix, "projector.matrix");
    const ProjectorMatrixReport &ma = a.projector_matrix->report, &mb = b.projector_matrix->report;
    EXPECT_EQ(ma.points_used, mb.points_used);
    EXPECT_EQ(ma.points_dropped, mb.points_dropped);
    ExpectNear(ma.rms_d, mb.rms_d, "rms_d");
    ExpectNear(ma.max_d, mb.max_d, "max_d");
    ExpectNear(ma.residual_sigma_d, mb.residual_sigma_d, "residual_sigma_d");
    EXPECT_EQ(ma.iterations, mb.iterations);
    EXPECT_EQ(ma.converged, mb.converged);
  }
  ExpectNear(a.projector.plane_centre_mm, b.projector.plane_centre_mm, "pose.plane_centre_mm");
  ExpectNear(a.projector.plane_axis, b.projector.plane_axis, "pose.plane_axis");
  ASSERT_EQ(a.projector.matrix_centre_mm.has_value(), b.projector.matrix_centre_mm.has_value());
  if (a.projector.matrix_centre_mm) {
    ExpectNear(*a.projector.matrix_centre_mm, *b.projector.matrix_centre_mm, "pose.centre");
    ExpectNear(*a.projector.optical_axis, *b.projector.optical_axis, "pose.optical_axis");
    ExpectNear(*a.projector.matrix_centre_distance_mm, *b.projector.matrix_centre_distance_mm,
               "pose.distance");
    ExpectNear(*a.projector.camera_projector_angle_deg, *b.projector.camera_projector_angle_deg,
               "pose.angle");
  }

  ASSERT_EQ(a.reference_ray.has_value(), b.reference_ray.has_value());
  if (a.reference_ray) {
    ExpectNear(a.reference_ray->point_mm, b.reference_ray->point_mm, "ray.point_mm");
    ExpectNear(a.reference_ray->direction, b.reference_ray->direction, "ray.direction");
  }
  ASSERT_EQ(a.reference_views.size(), b.reference_views.size());
  for (size_t i = 0; i < a.reference_views.size(); ++i) {
    EXPECT_EQ(a.reference_views[i].image, b.reference_views[i].image);
    ExpectNear(a.reference_views[i].centre_px, b.reference_views[i].centre_px, "cross.centre");
    ExpectNear(a.reference_views[i].world_mm, b.reference_views[i].world_mm, "cross.world");
    ExpectNear(a.reference_views[i].ray_residual_mm, b.reference_views[i].ray_residual_mm,
               "cross.residual");
  }
  ASSERT_EQ(a.screen_views.size(), b.screen_views.size());
  for (size_t i = 0; i < a.screen_views.size(); ++i) {
    const ScreenViewReport &x = a.screen_views[i], &y = b.screen_views[i];
    EXPECT_EQ(x.image, y.image);
    ExpectNear(x.z_mm, y.z_mm, "screen.z_mm");
    EXPECT_EQ(x.lines, y.lines);
    EXPECT_EQ(x.stripe_points, y.stripe_points);
    EXPECT_EQ(x.junctions, y.junctions);
    ExpectNear(x.plane_rms_mm, y.plane_rms_mm, "screen.plane_rms_mm");
    EXPECT_EQ(x.q_offset, y.q_offset);
    EXPECT_EQ(x.matrix_junctions, y.matrix_junctions);
  }
  ExpectNear(a.sigmas.stripe_centre_px, b.sigmas.stripe_centre_px, "sigmas.stripe_centre_px");
  ExpectNear(a.sigmas.target_point_px, b.sigmas.target_point_px, "sigmas.target_point_px");
  ExpectNear(a.sigmas.plane_mm, b.sigmas.plane_mm, "sigmas.plane_mm");
}

class CalibrationFile : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::path(::testing::TempDir()) / ("calibration_file_" + std::to_string(::getpid()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  static const SideCalibration& Calibration() {
    return testing::SessionCalibration(SessionKind::kLeftNoisy);
  }
  static std::string Text() { return CalibrationToYaml(Calibration(), kVersion); }

  // Writes `text` to a file and returns the error LoadCalibration gives.
  std::string LoadError(const std::string& text) {
    const fs::path path = dir_ / "bad.yaml";
    std::ofstream(path, std::ios::binary) << text;
    try {
      LoadCalibration(path);
    } catch (const CalibrationFileError& e) {
      const std::string what = e.what();
      EXPECT_EQ(what.rfind(path.string() + ": ", 0), 0u) << what;  // names the file first
      return what;
    }
    ADD_FAILURE() << "loaded a bad file";
    return "";
  }

  // Text with the first occurrence of `from` replaced by `to`.
  static std::string Replaced(const std::string& from, const std::string& to) {
    std::string text = Text();
    const size_t at = text.find(from);
    EXPECT_NE(at, std::string::npos) << from;
    if (at != std::string::npos) text.replace(at, from.size(), to);
    return text;
  }

  fs::path dir_;
};

TEST_F(CalibrationFile, RoundTripGivesBackEveryStoredValue) {
  const fs::path path = dir_ / "left.yaml";
  SaveCalibration(path, Calibration(), kVersion);
  const CalibrationRecord record = LoadCalibration(path);
  EXPECT_EQ(record.software_version, kVersion);
  EXPECT_EQ(record.format_version, kCalibrationFormatVersion);
  ExpectSameCalibration(Calibration(), record.calibration);
  // Saving what was loaded gives the same text.
  EXPECT_EQ(CalibrationToYaml(record.calibration, kVersion), Text());
}

TEST_F(CalibrationFile, IsReadableYamlWithFormatAndVersions) {
  const std::string text = Text();
  EXPECT_NE(text.find("format: bsls-calibration\n"), std::string::npos);
  EXPECT_NE(text.find("format_version: 1\n"), std::string::npos);
  EXPECT_NE(text.find(std::string("software_version: ") + kVersion + "\n"), std::string::npos);
  EXPECT_NE(text.find("side: left\n"), std::string::npos);
  EXPECT_NE(text.find("manifest_sha256: " + Calibration().manifest_sha256), std::string::npos);
  EXPECT_NE(text.find("target: {rows: 8, cols: 8, pitch_mm: 6.5, square_mm: 4}"),
            std::string::npos);
}

TEST_F(CalibrationFile, SaveReplacesAWholeFileAndLeavesNothingOnFailure) {
  const fs::path path = dir_ / "left.yaml";
  std::ofstream(path) << "old";
  SaveCalibration(path, Calibration(), kVersion);
  EXPECT_NO_THROW(LoadCalibration(path));
  int files = 0;
  for (const auto& entry : fs::directory_iterator(dir_)) files += entry.is_regular_file();
  EXPECT_EQ(files, 1);  // no temporary left behind
  EXPECT_THROW(SaveCalibration(dir_ / "missing_folder" / "left.yaml", Calibration(), kVersion),
               OutputError);
  EXPECT_FALSE(fs::exists(dir_ / "missing_folder"));
}

TEST_F(CalibrationFile, AnotherFormatVersionIsRefused) {
  const std::string what = LoadError(Replaced("format_version: 1\n", "format_version: 2\n"));
  EXPECT_NE(what.find("format_version 2 is not supported"), std::string::npos) << what;
  const std::string other = LoadError(Replaced("format: bsls-calibration", "format: other"));
  EXPECT_NE(other.find("format is 'other'"), std::string::npos) << other;
}

TEST_F(CalibrationFile, TruncatedFileIsRefused) {
  const std::string text = Text();
  for (const double fraction : {0.0, 0.1, 0.5, 0.9}) {
    const std::string cut = text.substr(0, static_cast<size_t>(fraction * text.size()));
    const std::string what = LoadError(cut);
    EXPECT_FALSE(what.empty()) << fraction;
  }
  EXPECT_NE(LoadError("").find("empty"), std::string::npos);
  // Cut at a line end: still YAML, but keys are missing.
  const std::string half = text.substr(0, text.rfind('\n', text.size() / 2) + 1);
  EXPECT_NE(LoadError(half).find("missing key"), std::string::npos);
}

TEST_F(CalibrationFile, CorruptFileIsRefused) {
  EXPECT_NE(LoadError("{{{ not yaml").find("not valid YAML"), std::string::npos);
  EXPECT_NE(LoadError("- a list\n- not a map\n").find("expected a YAML mapping"),
            std::string::npos);
}

// The head alone (what bslsd reads): the side and versions of a whole
// file, and the same refusals as LoadCalibration for the same faults in the
// head; a fault in the body is not its business.
TEST_F(CalibrationFile, TheHeadIsReadAlone) {
  const fs::path path = dir_ / "left.yaml";
  SaveCalibration(path, Calibration(), kVersion);
  const CalibrationHeader header = LoadCalibrationHeader(path);
  EXPECT_EQ(header.side, pattern::Side::kLeft);
  EXPECT_EQ(header.format_version, kCalibrationFormatVersion);
  EXPECT_EQ(header.software_version, kVersion);

  const fs::path right = dir_ / "right.yaml";
  std::ofstream(right, std::ios::binary) << Replaced("side: left\n", "side: right\n");
  EXPECT_EQ(LoadCalibrationHeader(right).side, pattern::Side::kRight);

  const fs::path body = dir_ / "body.yaml";
  std::ofstream(body, std::ios::binary) << Replaced("{width: 512", "{width: wide");
  EXPECT_EQ(LoadCalibrationHeader(body).side, pattern::Side::kLeft);
  EXPECT_THROW(LoadCalibration(body), CalibrationFileError);

  for (const std::string& text :
       {Replaced("format: bsls-calibration", "format: other"),
        Replaced("format_version: 1\n", "format_version: 2\n"),
        Replaced("side: left\n", "side: middle\n"), std::string("{{{ not yaml"),
        std::string("- a list\n"), std::string("")}) {
    const std::string from_load = LoadError(text);
    try {
      LoadCalibrationHeader(dir_ / "bad.yaml");
      ADD_FAILURE() << "read the head of a bad file: " << from_load;
    } catch (const CalibrationFileError& e) {
      EXPECT_EQ(e.what(), from_load);
    }
  }
  EXPECT_THROW(LoadCalibrationHeader(dir_ / "missing.yaml"), CalibrationFileError);
}

TEST_F(CalibrationFile, MissingKeyIsNamed) {
  const std::string what = LoadError(Replaced("    residual_sigma_px:", "    other_key:"));
  EXPECT_NE(what.find("missing key 'camera.report.residual_sigma_px'"), std::string::npos) << what;
}

TEST_F(CalibrationFile, WrongTypeIsNamed) {
  const std::string what = LoadError(Replaced("{width: 512", "{width: wide"));
  EXPECT_NE(what.find("'image.width' must be a whole number, not 'wide'"), std::string::npos)
      << what;
  const std::string list = LoadError(Replaced("translation_mm: [", "translation_mm: [1, "));
  EXPECT_NE(list.find("'camera.pose.translation_mm' must be a list of 3 numbers"),
            std::string::npos)
      << list;
}

// Found by the calibration-file fuzz target (issue 26): a list item written
// as a value (camera.views: [a, b]) threw yaml-cpp's BadSubscript out of
// CalibrationFromYaml; bsls-processd answered such a calibration with
// INTERNAL instead of INVALID_ARGUMENT.
TEST_F(CalibrationFile, AValueWhereAMappingBelongsIsNamed) {
  const std::string text = Text();
  const std::size_t views = text.find("  views:\n");
  ASSERT_NE(views, std::string::npos);
  const std::size_t end = text.find("\nprojector:", views);
  ASSERT_NE(end, std::string::npos);
  std::string damaged = text;
  damaged.replace(views, end - views, "  views: [a.png, b.png]");
  const std::string what = LoadError(damaged);
  EXPECT_NE(what.find("'camera.views[0]' must be a mapping with 'image'"), std::string::npos)
      << what;
}

TEST_F(CalibrationFile, NonFiniteNumberIsRefused) {
  const std::string what = LoadError(Replaced("intrinsics: {fx: ", "intrinsics: {fx: .nan, x: "));
  EXPECT_NE(what.find("'camera.intrinsics.fx' is not a finite number"), std::string::npos) << what;
  const std::string inf = LoadError(Replaced("plane_mm: ", "plane_mm: .inf\n  x: "));
  EXPECT_NE(inf.find("'uncertainty.plane_mm' is not a finite number"), std::string::npos) << inf;
}

TEST_F(CalibrationFile, MissingFileIsNamed) {
  try {
    LoadCalibration(dir_ / "none.yaml");
    FAIL() << "loaded a missing file";
  } catch (const CalibrationFileError& e) {
    EXPECT_NE(std::string(e.what()).find("none.yaml: no such file"), std::string::npos);
  }
}

}  // namespace
}  // namespace bsls::calibration
