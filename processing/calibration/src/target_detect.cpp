#include "bsls/calibration/target_detect.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <opencv2/imgproc.hpp>
#include <optional>

#include "bsls/calibration/calibration_error.h"

namespace bsls::calibration {
namespace {

// Fewer ground pixels than this: the white level is their median, not a plane.
constexpr int kMinPlaneFitPixels = 12;

bool Fail(std::string* error, const std::string& why) {
  if (error) *error = why;
  return false;
}

TargetDetection Failure(std::string why, int candidates) {
  TargetDetection detection;
  detection.error = std::move(why);
  detection.candidates = candidates;
  return detection;
}

std::string Format(double value, int decimals) {
  char buffer[32];
  std::snprintf(buffer, sizeof(buffer), "%.*f", decimals, value);
  return buffer;
}

std::string At(const cv::Point2d& p) { return "(" + Format(p.x, 1) + ", " + Format(p.y, 1) + ")"; }

// Least-squares homography (h33 = 1) taking `from` to `to`, on coordinates
// normalised to zero mean and unit spread; nullopt when degenerate.
std::optional<cv::Matx33d> FitHomography(const std::vector<cv::Point2d>& from,
                                         const std::vector<cv::Point2d>& to) {
  auto normaliser = [](const std::vector<cv::Point2d>& points) {
    cv::Point2d mean(0, 0);
    for (const auto& p : points) mean += p;
    mean *= 1.0 / points.size();
    double spread = 0.0;
    for (const auto& p : points) spread += cv::norm(p - mean);
    spread = spread > 0.0 ? spread / points.size() : 1.0;
    return cv::Matx33d(1 / spread, 0, -mean.x / spread, 0, 1 / spread, -mean.y / spread, 0, 0, 1);
  };
  const cv::Matx33d nf = normaliser(from);
  const cv::Matx33d nt = normaliser(to);
  cv::Mat a(static_cast<int>(2 * from.size()), 8, CV_64F);
  cv::Mat b(static_cast<int>(2 * from.size()), 1, CV_64F);
  for (size_t i = 0; i < from.size(); ++i) {
    const cv::Vec3d f = nf * cv::Vec3d(from[i].x, from[i].y, 1.0);
    const cv::Vec3d t = nt * cv::Vec3d(to[i].x, to[i].y, 1.0);
    const double row_x[8] = {f[0], f[1], 1, 0, 0, 0, -t[0] * f[0], -t[0] * f[1]};
    const double row_y[8] = {0, 0, 0, f[0], f[1], 1, -t[1] * f[0], -t[1] * f[1]};
    for (int k = 0; k < 8; ++k) {
      a.at<double>(static_cast<int>(2 * i), k) = row_x[k];
      a.at<double>(static_cast<int>(2 * i + 1), k) = row_y[k];
    }
    b.at<double>(static_cast<int>(2 * i)) = t[0];
    b.at<double>(static_cast<int>(2 * i + 1)) = t[1];
  }
  cv::Mat h;
  if (!cv::solve(a, b, h, cv::DECOMP_SVD)) return std::nullopt;
  const cv::Matx33d normalised(h.at<double>(0), h.at<double>(1), h.at<double>(2), h.at<double>(3),
                               h.at<double>(4), h.at<double>(5), h.at<double>(6), h.at<double>(7),
                               1.0);
  const cv::Matx33d result = nt.inv() * normalised * nf;
  if (!cv::checkRange(cv::Mat(result)) || std::abs(cv::determinant(result)) < 1e-12)
    return std::nullopt;
  return result;
}

cv::Point2d Apply(const cv::Matx33d& h, const cv::Point2d& p) {
  const cv::Vec3d q = h * cv::Vec3d(p.x, p.y, 1.0);
  return {q[0] / q[2], q[1] / q[2]};
}

// A dark region that passed the shape filters.
struct Candidate {
  cv::Rect box;       // bounding box of its pixels
  cv::Mat mask;       // CV_8UC1 255 on its pixels, box-sized
  double area = 0.0;  // pixel count
  cv::Point2d centre;
};

// Why dark regions were not taken as squares, for the error message.
struct Rejections {
  int border = 0;  // square-sized regions touching the image border
  int shape = 0;   // square-sized regions of the wrong shape
  int size = 0;    // square-like regions far from the median size
  int isolated = 0;
};

// Grey-level centre of gravity of the darkness of `c` (thesis 6.1, 6.3).
// Darkness is W(x, y) - grey, where the white level W is a plane fitted to
// the ground around the square: pixels further than ground_clearance_px from
// every candidate, within the ROI. Summed over the pixels within
// centroid_border_px of the square that are nearer to it than to any other
// candidate, so the whole blurred edge counts and the neighbours' does not.
// Signed weights: noise on the ground averages out instead of pulling the
// centre towards the middle of the region.
cv::Point2d CentreOfGravity(const cv::Mat& grey, const Candidate& c,
                            const std::vector<Candidate>& all, const TargetDetectParams& params) {
  const int reach = params.centroid_border_px + params.ground_window_px + 1;
  const cv::Rect roi = cv::Rect(c.box.x - reach, c.box.y - reach, c.box.width + 2 * reach,
                                c.box.height + 2 * reach) &
                       cv::Rect(0, 0, grey.cols, grey.rows);
  // Distance (px) to this square and to every other candidate in the ROI.
  cv::Mat own(roi.size(), CV_8UC1, cv::Scalar(255));
  cv::Mat others(roi.size(), CV_8UC1, cv::Scalar(255));
  own(c.box - roi.tl()).setTo(0, c.mask);
  bool any_other = false;
  for (const Candidate& o : all) {
    if (&o == &c) continue;
    const cv::Rect overlap = o.box & roi;
    if (overlap.empty()) continue;
    others(overlap - roi.tl()).setTo(0, o.mask(overlap - o.box.tl()));
    any_other = true;
  }
  cv::Mat d_own, d_other;
  cv::distanceTransform(own, d_own, cv::DIST_L2, cv::DIST_MASK_PRECISE);
  if (any_other) cv::distanceTransform(others, d_other, cv::DIST_L2, cv::DIST_MASK_PRECISE);
  const float border = static_cast<float>(params.centroid_border_px);
  const float clearance = static_cast<float>(params.ground_clearance_px);
  const float infinity = std::numeric_limits<float>::infinity();

  // Least-squares plane W = a + b x + c y on the ground (coordinates relative
  // to the square's box centre for conditioning).
  const double x0 = c.box.x + c.box.width / 2.0;
  const double y0 = c.box.y + c.box.height / 2.0;
  cv::Matx33d ata = cv::Matx33d::zeros();
  cv::Vec3d atb(0, 0, 0);
  std::vector<double> ground;
  for (int y = 0; y < roi.height; ++y) {
    const float* mine = d_own.ptr<float>(y);
    const float* theirs = any_other ? d_other.ptr<float>(y) : nullptr;
    const std::uint8_t* g = grey.ptr<std::uint8_t>(y + roi.y) + roi.x;
    for (int x = 0; x < roi.width; ++x) {
      const float other = theirs ? theirs[x] : infinity;
      if (mine[x] <= clearance || other <= clearance) continue;
      const cv::Vec3d row(1.0, x + roi.x - x0, y + roi.y - y0);
      ata += row * row.t();
      atb += row * static_cast<double>(g[x]);
      ground.push_back(g[x]);
    }
  }
  cv::Vec3d plane(255.0, 0.0, 0.0);  // no ground at all: darkness is 255 - grey
  cv::Mat solution;
  if (static_cast<int>(ground.size()) >= kMinPlaneFitPixels &&
      cv::solve(cv::Mat(ata), cv::Mat(atb), solution, cv::DECOMP_CHOLESKY)) {
    plane = cv::Vec3d(solution.at<double>(0), solution.at<double>(1), solution.at<double>(2));
  } else if (!ground.empty()) {
    std::nth_element(ground.begin(), ground.begin() + ground.size() / 2, ground.end());
    plane = cv::Vec3d(ground[ground.size() / 2], 0.0, 0.0);
  }

  double sum_w = 0.0, sum_x = 0.0, sum_y = 0.0;
  for (int y = 0; y < roi.height; ++y) {
    const float* mine = d_own.ptr<float>(y);
    const float* theirs = any_other ? d_other.ptr<float>(y) : nullptr;
    const std::uint8_t* g = grey.ptr<std::uint8_t>(y + roi.y) + roi.x;
    for (int x = 0; x < roi.width; ++x) {
      if (mine[x] > border) continue;
      if (theirs && mine[x] > 0.0f && theirs[x] <= mine[x]) continue;
      const double dx = x + roi.x - x0;
      const double dy = y + roi.y - y0;
      const double w = plane[0] + plane[1] * dx + plane[2] * dy - g[x];
      sum_w += w;
      sum_x += w * dx;
      sum_y += w * dy;
    }
  }
  if (!(sum_w > 0.0)) return c.centre;  // no contrast: the pixel centroid
  return {x0 + sum_x / sum_w, y0 + sum_y / sum_w};
}

// Keeps the dark regions that look like squares; counts the others.
std::vector<Candidate> FindCandidates(const cv::Mat& grey, const TargetDetectParams& params,
                                      Rejections* rejected) {
  cv::Mat smooth = grey;
  if (params.pre_blur_sigma_px > 0.0)
    cv::GaussianBlur(grey, smooth, cv::Size(0, 0), params.pre_blur_sigma_px,
                     params.pre_blur_sigma_px, cv::BORDER_REPLICATE);
  cv::Mat dark;
  cv::adaptiveThreshold(smooth, dark, 255, cv::ADAPTIVE_THRESH_MEAN_C, cv::THRESH_BINARY_INV,
                        params.threshold_block_px, params.threshold_offset);
  cv::Mat labels, stats, centroids;
  const int count = cv::connectedComponentsWithStats(dark, labels, stats, centroids, 8, CV_32S);
  const double max_area = params.max_area_fraction * grey.total();

  std::vector<Candidate> candidates;
  for (int i = 1; i < count; ++i) {
    const int area = stats.at<int>(i, cv::CC_STAT_AREA);
    if (area < params.min_area_px || area > max_area) continue;  // specks and background
    const cv::Rect box(stats.at<int>(i, cv::CC_STAT_LEFT), stats.at<int>(i, cv::CC_STAT_TOP),
                       stats.at<int>(i, cv::CC_STAT_WIDTH), stats.at<int>(i, cv::CC_STAT_HEIGHT));
    if (box.x == 0 || box.y == 0 || box.br().x == grey.cols || box.br().y == grey.rows) {
      ++rejected->border;  // cut by the image border: its centre would be wrong
      continue;
    }
    Candidate c;
    c.box = box;
    c.mask = (labels(box) == i);
    c.area = area;
    c.centre = {centroids.at<double>(i, 0), centroids.at<double>(i, 1)};
    // Shape of the outer contour (holes do not matter here).
    std::vector<std::vector<cv::Point>> contours;
    cv::findContours(c.mask.clone(), contours, cv::RETR_EXTERNAL, cv::CHAIN_APPROX_NONE);
    if (contours.empty()) continue;
    const auto& contour =
        *std::max_element(contours.begin(), contours.end(),
                          [](const auto& a, const auto& b) { return a.size() < b.size(); });
    // The contour and hull run through boundary pixel centres; compare pixel
    // counts with them grown by half a pixel all round (Pick's theorem:
    // pixels = area + perimeter / 2 + 1 for a lattice polygon).
    std::vector<cv::Point> hull;
    cv::convexHull(contour, hull);
    const double hull_pixels = cv::contourArea(hull) + cv::arcLength(hull, true) / 2.0 + 1.0;
    const cv::RotatedRect rect = cv::minAreaRect(contour);
    const double long_side = std::max(rect.size.width, rect.size.height) + 1.0;
    const double short_side = std::min(rect.size.width, rect.size.height) + 1.0;
    const double solidity = area / hull_pixels;
    const double fill = area / (long_side * short_side);
    const bool square = solidity >= params.min_solidity && fill >= params.min_fill &&
                        long_side / short_side <= params.max_aspect;
    if (!square) {
      ++rejected->shape;
      continue;
    }
    candidates.push_back(std::move(c));
  }
  if (candidates.empty()) return candidates;

  // Similar sizes: the squares are the majority of the square-like blobs.
  std::vector<double> areas;
  for (const Candidate& c : candidates) areas.push_back(c.area);
  std::nth_element(areas.begin(), areas.begin() + areas.size() / 2, areas.end());
  const double median_area = areas[areas.size() / 2];
  std::erase_if(candidates, [&](const Candidate& c) {
    const bool off = c.area > median_area * params.max_area_ratio ||
                     c.area * params.max_area_ratio < median_area;
    rejected->size += off;
    return off;
  });

  // Isolated blobs are clutter beside the target.
  if (candidates.size() >= 3) {
    std::vector<double> nearest(candidates.size(), std::numeric_limits<double>::infinity());
    for (size_t i = 0; i < candidates.size(); ++i)
      for (size_t j = 0; j < candidates.size(); ++j)
        if (i != j)
          nearest[i] = std::min(nearest[i], cv::norm(candidates[i].centre - candidates[j].centre));
    std::vector<double> sorted = nearest;
    std::nth_element(sorted.begin(), sorted.begin() + sorted.size() / 2, sorted.end());
    const double limit = sorted[sorted.size() / 2] * params.max_isolation;
    std::vector<Candidate> kept;
    for (size_t i = 0; i < candidates.size(); ++i) {
      if (nearest[i] > limit)
        ++rejected->isolated;
      else
        kept.push_back(std::move(candidates[i]));
    }
    candidates = std::move(kept);
  }
  return candidates;
}

std::string MissingReason(int found, int expected, const Rejections& r) {
  std::string why =
      "found " + std::to_string(found) + " of " + std::to_string(expected) + " target squares";
  std::vector<std::string> notes;
  if (r.border > 0)
    notes.push_back(std::to_string(r.border) + " dark blobs cut by the image border");
  if (r.shape > 0) notes.push_back(std::to_string(r.shape) + " not square");
  if (r.size > 0) notes.push_back(std::to_string(r.size) + " of another size");
  if (r.isolated > 0) notes.push_back(std::to_string(r.isolated) + " isolated");
  if (!notes.empty()) {
    why += " (rejected: ";
    for (size_t i = 0; i < notes.size(); ++i) why += (i ? ", " : "") + notes[i];
    why += ")";
  }
  return why;
}

}  // namespace

bool TargetDetectParams::IsValid(std::string* error) const {
  if (threshold_block_px < 3 || threshold_block_px % 2 == 0)
    return Fail(error, "target detection threshold_block_px must be odd and >= 3");
  if (!(threshold_offset > 0.0 && threshold_offset < 255.0))
    return Fail(error, "target detection threshold_offset must lie in (0, 255)");
  if (!(pre_blur_sigma_px >= 0.0 && pre_blur_sigma_px <= 10.0))
    return Fail(error, "target detection pre_blur_sigma_px must lie in [0, 10]");
  if (min_area_px < 4) return Fail(error, "target detection min_area_px must be >= 4");
  if (!(max_area_fraction > 0.0 && max_area_fraction <= 1.0))
    return Fail(error, "target detection max_area_fraction must lie in (0, 1]");
  if (!(min_solidity > 0.0 && min_solidity <= 1.0))
    return Fail(error, "target detection min_solidity must lie in (0, 1]");
  if (!(min_fill > 0.0 && min_fill <= 1.0))
    return Fail(error, "target detection min_fill must lie in (0, 1]");
  if (!(max_aspect >= 1.0 && std::isfinite(max_aspect)))
    return Fail(error, "target detection max_aspect must be >= 1 and finite");
  if (!(max_area_ratio > 1.0 && std::isfinite(max_area_ratio)))
    return Fail(error, "target detection max_area_ratio must be > 1 and finite");
  if (!(max_isolation > 1.0 && std::isfinite(max_isolation)))
    return Fail(error, "target detection max_isolation must be > 1 and finite");
  if (!(max_grid_residual > 0.0 && max_grid_residual < 0.5))
    return Fail(error, "target detection max_grid_residual must lie in (0, 0.5) cells");
  if (centroid_border_px < 0)
    return Fail(error, "target detection centroid_border_px must be >= 0");
  if (ground_clearance_px < 0)
    return Fail(error, "target detection ground_clearance_px must be >= 0");
  if (ground_window_px < 1) return Fail(error, "target detection ground_window_px must be >= 1");
  return true;
}

TargetDetection DetectTarget(const cv::Mat& grey, const TargetGeometry& target,
                             const TargetDetectParams& params) {
  std::string why;
  if (!params.IsValid(&why))
    throw CalibrationError(CalibrationErrorReason::kInvalidParams, "target detection: " + why);
  if (target.rows < 2 || target.cols < 2)
    throw CalibrationError(CalibrationErrorReason::kInvalidParams,
                           "target detection: the target needs at least 2 x 2 squares");
  if (grey.empty() || grey.type() != CV_8UC1)
    throw CalibrationError(CalibrationErrorReason::kInvalidInput,
                           "target detection: the image must be a non-empty CV_8UC1 frame");
  const int expected = target.rows * target.cols;
  const std::string grid = std::to_string(target.rows) + " x " + std::to_string(target.cols);

  Rejections rejected;
  std::vector<Candidate> candidates = FindCandidates(grey, params, &rejected);
  const int found = static_cast<int>(candidates.size());
  if (found < expected) return Failure(MissingReason(found, expected, rejected), found);
  if (found > expected)
    return Failure("found " + std::to_string(found) + " square-like blobs where the " + grid +
                       " target has " + std::to_string(expected) + " squares",
                   found);

  std::vector<cv::Point2d> centres;
  for (const Candidate& c : candidates)
    centres.push_back(CentreOfGravity(grey, c, candidates, params));

  // The four grid corners: extremes of x + y and x - y (rotation < 45 deg).
  int tl = 0, tr = 0, br = 0, bl = 0;
  for (int i = 0; i < found; ++i) {
    const cv::Point2d& p = centres[i];
    if (p.x + p.y < centres[tl].x + centres[tl].y) tl = i;
    if (p.x + p.y > centres[br].x + centres[br].y) br = i;
    if (p.x - p.y > centres[tr].x - centres[tr].y) tr = i;
    if (p.x - p.y < centres[bl].x - centres[bl].y) bl = i;
  }
  if (tl == tr || tl == br || tl == bl || tr == br || tr == bl || br == bl)
    return Failure("the squares have no four distinct grid corners", found);
  const double last_col = target.cols - 1;
  const double last_row = target.rows - 1;
  std::optional<cv::Matx33d> homography =
      FitHomography({centres[tl], centres[tr], centres[br], centres[bl]},
                    {{0.0, 0.0}, {last_col, 0.0}, {last_col, last_row}, {0.0, last_row}});
  if (!homography) return Failure("the corners of the " + grid + " grid are degenerate", found);

  // Assign, refit on every square, assign again.
  std::vector<cv::Point> cells(found);
  double worst = 0.0;
  for (int pass = 0; pass < 2; ++pass) {
    std::vector<cv::Point2d> mapped;
    for (const cv::Point2d& centre : centres) mapped.push_back(Apply(*homography, centre));
    std::vector<int> owner(expected, -1);
    worst = 0.0;
    for (int i = 0; i < found; ++i) {
      const int col = static_cast<int>(std::lround(mapped[i].x));
      const int row = static_cast<int>(std::lround(mapped[i].y));
      const double residual = std::hypot(mapped[i].x - col, mapped[i].y - row);
      if (row < 0 || row >= target.rows || col < 0 || col >= target.cols ||
          residual > params.max_grid_residual)
        return Failure("the squares do not form a " + grid + " grid: the square at " +
                           At(centres[i]) + " lies " + Format(residual, 2) +
                           " cells from the nearest grid node",
                       found);
      if (owner[row * target.cols + col] >= 0)
        return Failure("the squares do not form a " + grid + " grid: the squares at " +
                           At(centres[owner[row * target.cols + col]]) + " and " + At(centres[i]) +
                           " both fall on row " + std::to_string(row) + ", column " +
                           std::to_string(col),
                       found);
      owner[row * target.cols + col] = i;
      cells[i] = {col, row};
      worst = std::max(worst, residual);
    }
    if (pass == 0) {
      std::vector<cv::Point2d> nodes;
      for (const cv::Point& cell : cells) nodes.emplace_back(cell.x, cell.y);
      homography = FitHomography(centres, nodes);
      if (!homography)
        return Failure("the " + grid + " grid fit through the squares is degenerate", found);
    }
  }

  TargetDetection detection;
  detection.ok = true;
  detection.candidates = found;
  detection.max_grid_residual = worst;
  detection.squares.resize(expected);
  for (int i = 0; i < found; ++i) {
    TargetSquare& square = detection.squares[cells[i].y * target.cols + cells[i].x];
    square.row = cells[i].y;
    square.col = cells[i].x;
    square.centre = centres[i];
    square.area_px = candidates[i].area;
  }
  return detection;
}

}  // namespace bsls::calibration
