#include "brick_scoring.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <opencv2/imgproc.hpp>

#include "bsls/extraction/thinning.h"

namespace bsls::extraction::testing {
namespace {

bool NearSegmentRow(const BrickTruth& t, int y, double margin) {
  for (double r : t.segment_rows)
    if (std::abs(y - r) <= 0.5 * t.segment_width + margin) return true;
  return false;
}

}  // namespace

std::ostream& operator<<(std::ostream& os, const MaskScore& s) {
  return os << "recall " << s.recall << ", dark " << s.recall_dark << ", false positive "
            << s.false_positive << ", width error " << s.width_error << " px, bridges "
            << s.bridges;
}

std::ostream& operator<<(std::ostream& os, const SkeletonScore& s) {
  return os << "junctions within 1.5 px " << s.junctions_within_1_5 << ", dark "
            << s.junctions_within_1_5_dark << ", worst " << s.worst_junction
            << " px, line coverage " << s.line_coverage << ", dark " << s.line_coverage_dark
            << ", merges " << s.merges << ", false junctions " << s.false_junctions
            << ", one pixel wide " << s.one_pixel_wide;
}

std::vector<cv::Point> JunctionPixels(const cv::Mat& skeleton) {
  std::vector<cv::Point> out;
  for (int y = 0; y < skeleton.rows; ++y)
    for (int x = 0; x < skeleton.cols; ++x)
      if (skeleton.at<unsigned char>(y, x) && Degree(skeleton, x, y) >= 3) out.push_back({x, y});
  return out;
}

cv::Mat ScoredRegion(const BrickTruth& truth) {
  cv::Mat inner;
  cv::erode(truth.inside, inner, cv::getStructuringElement(cv::MORPH_ELLIPSE, {17, 17}));
  return inner;
}

MaskScore ScoreMask(const cv::Mat& mask, const BrickTruth& t) {
  const cv::Mat region = ScoredRegion(t);
  MaskScore s;
  int n = 0, hit = 0, nd = 0, hitd = 0, wn = 0;
  double werr = 0.0;
  for (int p = 0; p < t.lines; ++p)
    for (int y = 0; y < mask.rows; ++y) {
      const int x = static_cast<int>(std::lround(t.line_x[p][y]));
      if (x < 0 || x >= mask.cols || !region.at<unsigned char>(y, x)) continue;
      const bool in = mask.at<unsigned char>(y, x) != 0;
      const bool off_segments = !NearSegmentRow(t, y, 3.0);
      if (t.dark.at<unsigned char>(y, x)) {
        ++nd;
        hitd += in;
        continue;
      }
      ++n;
      hit += in;
      if (in && off_segments) {
        int a = x, b = x;
        while (a > 0 && mask.at<unsigned char>(y, a - 1)) --a;
        while (b + 1 < mask.cols && mask.at<unsigned char>(y, b + 1)) ++b;
        werr += (b - a + 1) - t.line_width[p];
        ++wn;
      }
      if (p + 1 < t.lines && off_segments) {
        const int x2 = static_cast<int>(std::lround(t.line_x[p + 1][y]));
        if (x2 < mask.cols && cv::countNonZero(mask.row(y).colRange(x, x2 + 1)) == x2 - x + 1)
          ++s.bridges;
      }
    }
  s.recall = n ? static_cast<double>(hit) / n : 1.0;
  s.recall_dark = nd ? static_cast<double>(hitd) / nd : 1.0;
  s.width_error = wn ? werr / wn : 0.0;
  cv::Mat distance;
  cv::distanceTransform(t.stroke == 0, distance, cv::DIST_L2, 3);
  int total = 0, far = 0;
  for (int y = 0; y < mask.rows; ++y)
    for (int x = 0; x < mask.cols; ++x)
      if (mask.at<unsigned char>(y, x)) {
        ++total;
        far += distance.at<float>(y, x) > 2.0f;
      }
  s.false_positive = total ? static_cast<double>(far) / total : 0.0;
  return s;
}

SkeletonScore ScoreSkeleton(const cv::Mat& skeleton, const BrickTruth& t) {
  const cv::Mat region = ScoredRegion(t);
  SkeletonScore s;
  const std::vector<cv::Point> junctions = JunctionPixels(skeleton);
  int n = 0, ok = 0, nd = 0, okd = 0;
  for (const cv::Point2d& j : t.junctions) {
    double best = std::numeric_limits<double>::infinity();
    for (const cv::Point& q : junctions) best = std::min(best, std::hypot(q.x - j.x, q.y - j.y));
    s.worst_junction = std::max(s.worst_junction, best);
    const bool good = best <= 1.5;
    if (t.dark.at<unsigned char>(static_cast<int>(std::lround(j.y)),
                                 static_cast<int>(std::lround(j.x)))) {
      ++nd;
      okd += good;
    } else {
      ++n;
      ok += good;
    }
  }
  s.junctions_within_1_5 = n ? static_cast<double>(ok) / n : 1.0;
  s.junctions_within_1_5_dark = nd ? static_cast<double>(okd) / nd : 1.0;

  // False junctions: clusters of junction pixels far from every true one,
  // well inside the region where the true ones are listed.
  cv::Mat deep;
  cv::erode(t.inside, deep, cv::getStructuringElement(cv::MORPH_ELLIPSE, {41, 41}));
  cv::Mat far = cv::Mat::zeros(skeleton.size(), CV_8UC1);
  for (const cv::Point& q : junctions) {
    if (!deep.at<unsigned char>(q)) continue;
    double best = std::numeric_limits<double>::infinity();
    for (const cv::Point2d& j : t.junctions)
      best = std::min(best, std::hypot(q.x - j.x, q.y - j.y));
    if (best > 3.0) far.at<unsigned char>(q) = 255;
  }
  s.false_junctions = CountComponents(far);

  // Coverage of the lines and merges between them.
  int rows = 0, covered = 0, rows_dark = 0, covered_dark = 0;
  for (int y = 0; y < skeleton.rows; ++y) {
    const bool off_segments = !NearSegmentRow(t, y, 3.0);
    for (int p = 0; p < t.lines; ++p) {
      const double cx = t.line_x[p][y];
      const int x = static_cast<int>(std::lround(cx));
      if (x < 2 || x + 2 >= skeleton.cols || !region.at<unsigned char>(y, x)) continue;
      bool found = false;
      for (int dx = -2; dx <= 2; ++dx)
        if (skeleton.at<unsigned char>(y, x + dx) && std::abs(x + dx - cx) <= 1.5) found = true;
      if (t.dark.at<unsigned char>(y, x)) {
        ++rows_dark;
        covered_dark += found;
      } else {
        ++rows;
        covered += found;
      }
      // Between this line and the next, off the segment rows, nothing may be set.
      if (p + 1 < t.lines && off_segments) {
        const double nx = t.line_x[p + 1][y];
        for (int xx = static_cast<int>(std::ceil(cx + 3.0)); xx <= nx - 3.0; ++xx)
          if (xx >= 0 && xx < skeleton.cols && region.at<unsigned char>(y, xx) &&
              skeleton.at<unsigned char>(y, xx))
            ++s.merges;
      }
    }
  }
  s.line_coverage = rows ? static_cast<double>(covered) / rows : 1.0;
  s.line_coverage_dark = rows_dark ? static_cast<double>(covered_dark) / rows_dark : 1.0;
  s.one_pixel_wide = cv::countNonZero(MakeOnePixelWide(skeleton) != skeleton) == 0;
  return s;
}

}  // namespace bsls::extraction::testing
