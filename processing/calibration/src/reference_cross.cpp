#include "bsls/calibration/reference_cross.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>
#include <stdexcept>

namespace bsls::calibration {
namespace {

constexpr double kPi = 3.14159265358979323846;

// A polynomial a0 + a1 t + a2 t^2 in t = (s - origin), fitted to (s, value)
// samples by least squares, refitted once without samples more than
// max(3 rms, 1 px) off; rms is that of the kept samples.
struct Parabola {
  double origin = 0;
  Eigen::Vector3d a = Eigen::Vector3d::Zero();
  double rms = 0;
  int kept = 0;
  double operator()(double s) const {
    const double t = s - origin;
    return a[0] + t * (a[1] + t * a[2]);
  }
};

std::optional<Parabola> FitParabola(const std::vector<cv::Point2d>& samples, double origin) {
  std::vector<bool> use(samples.size(), true);
  Parabola fit;
  fit.origin = origin;
  for (int pass = 0; pass < 2; ++pass) {
    const int n = static_cast<int>(std::count(use.begin(), use.end(), true));
    if (n < 6) return std::nullopt;
    Eigen::MatrixXd A(n, 3);
    Eigen::VectorXd b(n);
    for (size_t i = 0, k = 0; i < samples.size(); ++i) {
      if (!use[i]) continue;
      const double t = samples[i].x - origin;
      A.row(static_cast<Eigen::Index>(k)) << 1.0, t, t * t;
      b[static_cast<Eigen::Index>(k++)] = samples[i].y;
    }
    fit.a = A.colPivHouseholderQr().solve(b);
    fit.rms = std::sqrt((A * fit.a - b).squaredNorm() / n);
    fit.kept = n;
    const double limit = std::max(3.0 * fit.rms, 1.0);
    for (size_t i = 0; i < samples.size(); ++i)
      use[i] = std::abs(samples[i].y - fit(samples[i].x)) <= limit;
  }
  return fit;
}

// The strongest Hough line within `max_lean` of the direction whose normal
// makes angle `normal` with the x axis, as (rho, theta); nullopt if none.
// Also returns the votes of the strongest other line of that direction at
// least `apart` px away (a brick frame has many parallel lines; a cross one).
struct HoughPick {
  cv::Vec2f line;
  int votes = 0;
  int rival_votes = 0;
};

std::optional<HoughPick> Pick(const std::vector<cv::Vec3f>& lines, double normal, double max_lean,
                              double apart) {
  std::optional<HoughPick> best;
  for (const cv::Vec3f& l : lines) {
    double d = std::abs(l[1] - normal);
    d = std::min(d, kPi - d);
    if (d > max_lean) continue;
    const int votes = static_cast<int>(l[2]);
    if (!best) {
      best = HoughPick{{l[0], l[1]}, votes, 0};
      continue;
    }
    // Distance between the lines along the picked line's normal, near the image.
    double rho = l[0];
    if (std::abs(l[1] - best->line[1]) > kPi / 2) rho = -rho;
    if (std::abs(rho - best->line[0]) > apart)
      best->rival_votes = std::max(best->rival_votes, votes);
  }
  return best;
}

}  // namespace

bool CrossParams::IsValid(std::string* error) const {
  if (!extraction.IsValid(error) || !centre.IsValid(error)) return false;
  auto fail = [error](const char* why) {
    if (error) *error = why;
    return false;
  };
  if (min_arm_px < 6) return fail("min_arm_px must be at least 6");
  if (clearance_px < 0) return fail("clearance_px must not be negative");
  if (fit_reach_px <= clearance_px + 6) return fail("fit_reach_px must exceed clearance_px + 6");
  if (!(max_rms_px > 0)) return fail("max_rms_px must be positive");
  if (!(max_lean_deg > 0 && max_lean_deg < 45)) return fail("max_lean_deg must lie in (0, 45)");
  return true;
}

// Slide 1 (thesis Figure 1.1) on the calibration screen.
std::optional<ReferenceCross> FindReferenceCross(const cv::Mat& grey, const CrossParams& params,
                                                 std::string* why) {
  if (grey.empty() || grey.type() != CV_8UC1)
    throw std::invalid_argument("FindReferenceCross: frame must be a non-empty CV_8UC1 image");
  std::string bad;
  if (!params.IsValid(&bad)) throw std::invalid_argument("FindReferenceCross: " + bad);
  auto fail = [why](const std::string& reason) -> std::optional<ReferenceCross> {
    if (why) *why = reason;
    return std::nullopt;
  };

  const extraction::ExtractionResult features =
      extraction::ExtractFeatures(grey, params.extraction);
  std::vector<cv::Vec3f> lines;
  cv::HoughLines(features.skeleton, lines, 1.0, kPi / 360, 2 * params.min_arm_px);
  const double lean = params.max_lean_deg * kPi / 180;
  const auto vertical = Pick(lines, 0.0, lean, 8.0);
  const auto horizontal = Pick(lines, kPi / 2, lean, 8.0);
  if (!vertical) return fail("no vertical stroke");
  if (!horizontal) return fail("no horizontal stroke");
  // A cross has one line of each direction; the brick slide has many.
  if (vertical->rival_votes > vertical->votes / 2 ||
      horizontal->rival_votes > horizontal->votes / 2)
    return fail("more than one line of a direction: not slide 1");

  // The rough centre where the two Hough lines meet: x cos t + y sin t = rho.
  const cv::Matx22d m(std::cos(vertical->line[1]), std::sin(vertical->line[1]),
                      std::cos(horizontal->line[1]), std::sin(horizontal->line[1]));
  cv::Vec2d rough;
  if (!cv::solve(m, cv::Vec2d(vertical->line[0], horizontal->line[0]), rough))
    return fail("strokes parallel");
  const double xc = rough[0], yc = rough[1];
  if (xc < 0 || yc < 0 || xc > grey.cols - 1 || yc > grey.rows - 1)
    return fail("centre outside the frame");

  auto x_on_vertical = [&](double y) {
    return (vertical->line[0] - y * std::sin(vertical->line[1])) / std::cos(vertical->line[1]);
  };
  auto y_on_horizontal = [&](double x) {
    return (horizontal->line[0] - x * std::cos(horizontal->line[1])) /
           std::sin(horizontal->line[1]);
  };

  ReferenceCross cross;
  int above = 0, below = 0, left = 0, right = 0;
  for (int y = 0; y < grey.rows; ++y) {
    if (std::abs(y - yc) <= params.clearance_px || std::abs(y - yc) > params.fit_reach_px) continue;
    if (const auto x = extraction::StripeCentreInRow(grey, y, x_on_vertical(y), params.centre)) {
      cross.vertical.emplace_back(*x, y);
      (y < yc ? above : below) += 1;
    }
  }
  for (int x = 0; x < grey.cols; ++x) {
    if (std::abs(x - xc) <= params.clearance_px || std::abs(x - xc) > params.fit_reach_px) continue;
    if (const auto y =
            extraction::StripeCentreInColumn(grey, x, y_on_horizontal(x), params.centre)) {
      cross.horizontal.emplace_back(x, *y);
      (x < xc ? left : right) += 1;
    }
  }
  const int arm = params.min_arm_px - params.clearance_px;
  if (above < arm || below < arm) return fail("vertical stroke too short on a side of the centre");
  if (left < arm || right < arm) return fail("horizontal stroke too short on a side of the centre");

  // Fits as x(y) and y(x): swap the vertical samples' coordinates.
  std::vector<cv::Point2d> v_swapped;
  for (const cv::Point2d& p : cross.vertical) v_swapped.emplace_back(p.y, p.x);
  const auto xv = FitParabola(v_swapped, yc);
  const auto yh = FitParabola(cross.horizontal, xc);
  if (!xv || !yh) return fail("too few centres on a stroke");
  cross.vertical_rms_px = xv->rms;
  cross.horizontal_rms_px = yh->rms;
  if (xv->rms > params.max_rms_px || yh->rms > params.max_rms_px)
    return fail("a stroke is not straight (centre scatter " +
                std::to_string(std::max(xv->rms, yh->rms)) + " px)");

  // Where x = xv(y) meets y = yh(x): fixed-point iteration (both strokes
  // lean little, so it contracts fast).
  double x = xc, y = yc;
  for (int i = 0; i < 50; ++i) {
    const double nx = (*xv)(y), ny = (*yh)(nx);
    const bool done = std::abs(nx - x) < 1e-9 && std::abs(ny - y) < 1e-9;
    x = nx;
    y = ny;
    if (done) break;
  }
  if (std::hypot(x - xc, y - yc) > params.clearance_px)
    return fail("strokes' fits do not meet at the cross");
  cross.centre = {x, y};
  return cross;
}

}  // namespace bsls::calibration
