#include "bsls/reconstruction/calibrated_model.h"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <stdexcept>
#include <vector>

namespace bsls::reconstruction {
namespace {

bool Fail(std::string* why, const std::string& reason) {
  if (why) *why = reason;
  return false;
}

}  // namespace

TriangulationModel ModelOfCalibration(const calibration::SideCalibration& calibration,
                                      PlaneModelKind planes) {
  CalibratedGeometry geometry;
  geometry.camera = calibration.camera.model;
  geometry.light_plane = planes == PlaneModelKind::kPerspective
                             ? LightPlanesOfModel(calibration.perspective.model)
                             : LightPlanesOfModel(calibration.parallel.model);
  if (calibration.projector_matrix) geometry.projector = calibration.projector_matrix->model;

  TriangulationModel model;
  model.side = calibration.side;
  model.geometry = geometry;
  // Each sigma the calibration measured replaces the default guess.
  UncertaintyParams& u = model.uncertainty;
  const calibration::UncertaintySigmas& s = calibration.sigmas;
  if (s.stripe_centre_px > 0.0) u.stripe_centre_sigma_px = s.stripe_centre_px;
  if (s.target_point_px > 0.0) u.camera_reprojection_sigma_px = s.target_point_px;
  const double plane_rms = planes == PlaneModelKind::kPerspective
                               ? calibration.perspective.report.rms_mm
                               : calibration.parallel.report.rms_mm;
  if (plane_rms > 0.0) u.light_plane_sigma_mm = plane_rms;
  if (calibration.projector_matrix && calibration.projector_matrix->report.residual_sigma_d > 0.0)
    u.projector_residual_sigma_d = calibration.projector_matrix->report.residual_sigma_d;
  return model;
}

TriangulationModel ModelOfKnownDevices(pattern::Side side, const geometry::PinholeModel& camera,
                                       const geometry::PinholeModel& projector) {
  TriangulationModel model;
  model.side = side;
  model.geometry = CalibratedGeometry{camera, LightPlanesOfProjector(projector, side), projector};
  return model;
}

calibration::SideCalibration CalibrationOfKnownDevices(pattern::Side side,
                                                       const geometry::PinholeModel& camera,
                                                       const geometry::PinholeModel& projector,
                                                       const pattern::PatternSpec& pattern,
                                                       int width, int height,
                                                       const std::vector<double>& screen_z_mm) {
  if (screen_z_mm.size() < 2)
    throw std::invalid_argument("CalibrationOfKnownDevices: two screen heights are needed");
  calibration::SideCalibration cal;
  cal.side = side;
  cal.width = width;
  cal.height = height;
  cal.pattern = pattern;
  cal.camera.model = camera;
  cal.projector_matrix = calibration::ProjectorMatrixFit{};
  cal.projector_matrix->model = projector;
  // Points of every line's plane: the projector's rays through the line's
  // top, middle and bottom, cut at each screen height.
  std::vector<calibration::StripePoint> points;
  for (int p = 0; p < pattern.lines; ++p)
    for (double z : screen_z_mm)
      for (double t :
           {-static_cast<double>(pattern.rows), 0.0, static_cast<double>(pattern.rows)}) {
        const geometry::Ray ray = projector.BackProject({pattern::SFromU(side, p), t});
        if (std::abs(ray.direction.z()) < 1e-9) continue;
        const double k = (z - ray.origin.z()) / ray.direction.z();
        points.push_back({ray.origin + k * ray.direction, p});
      }
  cal.perspective = calibration::FitPerspectivePlaneModel(points);
  for (double z : screen_z_mm) cal.screen_views.push_back({"", z});
  return cal;
}

bool SlideRowParams::IsValid(std::string* error) const {
  if (!(agreement_rows > 0.0 && agreement_rows < 1.0))
    return Fail(error, "SlideRowParams.agreement_rows must lie in (0, 1) rows");
  if (!(min_agreement > 0.0 && min_agreement <= 1.0))
    return Fail(error, "SlideRowParams.min_agreement must lie in (0, 1]");
  if (min_junctions < 1) return Fail(error, "SlideRowParams.min_junctions must be >= 1");
  return true;
}

// Contracts section 2: q is known up to an even offset; the projector matrix
// (thesis eq. 2.16) says which slide row each seen junction came from.
std::optional<SlidePoint> JunctionOnSlide(const calibration::SideCalibration& calibration,
                                          const cv::Point2d& image, int p) {
  return JunctionOnSlide(calibration, calibration.camera.model.BackProject({image.x, image.y}), p);
}

std::optional<SlidePoint> JunctionOnSlide(const calibration::SideCalibration& calibration,
                                          const geometry::Ray& ray, int p) {
  if (!calibration.projector_matrix) return std::nullopt;
  const calibration::LightPlane plane = calibration.perspective.model.PlaneOfLine(p);
  const auto world = plane.Intersect(ray);
  if (!world) return std::nullopt;
  const auto slide = calibration.projector_matrix->model.Project(*world);
  if (!slide) return std::nullopt;
  return SlidePoint{*world, *slide};
}

int EvenRowOffset(std::vector<double>* residues) {
  const auto mid = residues->begin() + static_cast<std::ptrdiff_t>(residues->size() / 2);
  std::nth_element(residues->begin(), mid, residues->end());
  return 2 * static_cast<int>(std::lround(*mid / 2.0));
}

std::optional<int> SlideRowOffset(const decoder::DecodeResult& decode,
                                  const calibration::SideCalibration& calibration, std::string* why,
                                  const SlideRowParams& params) {
  std::string error;
  if (!params.IsValid(&error)) {
    Fail(why, error);
    return std::nullopt;
  }
  if (!calibration.projector_matrix) {
    Fail(why, "the calibration has no projector matrix (its manifest had no reference views)");
    return std::nullopt;
  }
  std::vector<double> residue;  // slide row t minus the decoded q, per junction
  for (const decoder::DecodedJunction& j : decode.junctions) {
    if (j.interpolated) continue;
    if (const auto on = JunctionOnSlide(calibration, j.position, j.p))
      residue.push_back(on->slide.y() - j.q);
  }
  if (static_cast<int>(residue.size()) < params.min_junctions) {
    Fail(why, std::to_string(residue.size()) + " junctions could be placed on the slide, " +
                  std::to_string(params.min_junctions) + " are needed");
    return std::nullopt;
  }
  std::vector<double> sorted = residue;
  const int offset = EvenRowOffset(&sorted);
  const double median = sorted[sorted.size() / 2];
  const auto agree = std::count_if(residue.begin(), residue.end(), [&](double r) {
    return std::abs(r - offset) <= params.agreement_rows;
  });
  const double fraction = static_cast<double>(agree) / static_cast<double>(residue.size());
  if (fraction < params.min_agreement) {
    Fail(why, "only " + std::to_string(agree) + " of " + std::to_string(residue.size()) +
                  " junctions agree with slide-row offset " + std::to_string(offset) +
                  " (median slide row - q = " + std::to_string(median) + ")");
    return std::nullopt;
  }
  return offset;
}

void MakeRowsAbsolute(int q_offset, decoder::DecodeResult* decode) {
  if (q_offset % 2 != 0)
    throw std::invalid_argument("MakeRowsAbsolute: q offset " + std::to_string(q_offset) +
                                " is odd (contracts section 2: rows repeat every 2)");
  if (decode->q_absolute)
    throw std::invalid_argument("MakeRowsAbsolute: the decode's rows are already absolute");
  for (decoder::DecodedJunction& j : decode->junctions) j.q += q_offset;
  decode->q_absolute = true;
}

}  // namespace bsls::reconstruction
