#include "bsls/interpretation/junction_detect.h"

#include <algorithm>
#include <cmath>
#include <deque>
#include <stdexcept>

#include "bsls/interpretation/chain_code.h"

namespace bsls::interpretation {
namespace {

// Pixels on the border of the (2r+1)^2 window, in order around it.
std::vector<cv::Point> Ring(cv::Point c, int r) {
  std::vector<cv::Point> ring;
  for (int x = -r; x <= r; ++x) ring.push_back({c.x + x, c.y - r});
  for (int y = -r + 1; y <= r; ++y) ring.push_back({c.x + r, c.y + y});
  for (int x = r - 1; x >= -r; --x) ring.push_back({c.x + x, c.y + r});
  for (int y = r - 1; y > -r; --y) ring.push_back({c.x - r, c.y + y});
  return ring;
}

struct Subset {
  cv::Point best;
  int distance = -1;
};

// Stages 3-4: connected subsets of set border pixels, each represented by its
// pixel with the shortest path (inside the window) to the candidate.
std::vector<Subset> BorderSubsets(const cv::Mat& sk, cv::Point c, int r) {
  const int size = 2 * r + 1;
  cv::Mat dist(size, size, CV_32S, cv::Scalar(-1));
  auto is_set = [&](cv::Point p) {
    return p.x >= 0 && p.y >= 0 && p.x < sk.cols && p.y < sk.rows && sk.at<uchar>(p) != 0;
  };
  std::deque<cv::Point> queue{c};
  dist.at<int>(r, r) = 0;
  while (!queue.empty()) {
    const cv::Point p = queue.front();
    queue.pop_front();
    const int d = dist.at<int>(p.y - c.y + r, p.x - c.x + r);
    for (int code = 0; code < 8; ++code) {
      const cv::Point q = p + CodeStep(code);
      if (std::abs(q.x - c.x) > r || std::abs(q.y - c.y) > r || !is_set(q)) continue;
      int& dq = dist.at<int>(q.y - c.y + r, q.x - c.x + r);
      if (dq >= 0) continue;
      dq = d + 1;
      queue.push_back(q);
    }
  }
  const std::vector<cv::Point> ring = Ring(c, r);
  const int n = static_cast<int>(ring.size());
  // Start the walk round the ring at an unset pixel so no subset is split.
  int start = -1;
  for (int i = 0; i < n; ++i)
    if (!is_set(ring[i])) {
      start = i;
      break;
    }
  std::vector<Subset> subsets;
  if (start < 0) return subsets;  // a fully set ring is not a junction
  Subset current;
  bool open = false;
  for (int k = 1; k <= n; ++k) {
    const cv::Point p = ring[(start + k) % n];
    if (is_set(p)) {
      open = true;
      const int d = dist.at<int>(p.y - c.y + r, p.x - c.x + r);
      if (d >= 0 && (current.distance < 0 || d < current.distance)) {
        current.distance = d;
        current.best = p;
      }
    } else if (open) {
      if (current.distance >= 0) subsets.push_back(current);
      current = Subset{};
      open = false;
    }
  }
  return subsets;
}

// Intersection of line a0-a1 with line b0-b1, if they are not parallel.
bool Intersect(cv::Point2d a0, cv::Point2d a1, cv::Point2d b0, cv::Point2d b1, cv::Point2d* out) {
  const cv::Point2d da = a1 - a0, db = b1 - b0;
  const double den = da.x * db.y - da.y * db.x;
  if (std::abs(den) < 1e-9) return false;
  const double t = ((b0.x - a0.x) * db.y - (b0.y - a0.y) * db.x) / den;
  *out = a0 + t * da;
  return true;
}

}  // namespace

bool JunctionParams::IsValid(std::string* error) const {
  auto fail = [error](const char* why) {
    if (error) *error = why;
    return false;
  };
  if (min_radius < 1 || max_radius < min_radius || max_radius > 10)
    return fail("junction window radii must satisfy 1 <= min_radius <= max_radius <= 10");
  if (vertical_tolerance_deg <= 0 || vertical_tolerance_deg >= 90 ||
      horizontal_tolerance_deg <= 0 || horizontal_tolerance_deg >= 90 ||
      opposite_tolerance_deg <= 0 || opposite_tolerance_deg >= 90)
    return fail("junction angle tolerances must lie in (0, 90) degrees");
  if (max_merge_edge < 0 || max_merge_edge > 50)
    return fail("max_merge_edge must lie in 0..50 pixels");
  return true;
}

JunctionAttribute AttributeForSegment(pattern::Side side, double side_dx) {
  // Direct junctions send their segment towards growing p.
  const bool towards_growing_p = (side_dx * pattern::ImageDirectionOfIncreasingP(side)) > 0;
  return towards_growing_p ? JunctionAttribute::kDirect : JunctionAttribute::kCorresponding;
}

// Thesis 5.2.3.1: detect a T-junction and its centre (JCP).
JunctionDetection DetectJunction(const cv::Mat& skeleton, cv::Point candidate, pattern::Side side,
                                 const JunctionParams& params) {
  if (skeleton.empty() || skeleton.type() != CV_8UC1)
    throw std::invalid_argument("DetectJunction: skeleton must be a non-empty CV_8UC1 image");
  std::string why;
  if (!params.IsValid(&why)) throw std::invalid_argument("DetectJunction: " + why);

  JunctionDetection out;
  out.centre = cv::Point2d(candidate.x, candidate.y);
  // Stages 2-3: the 7x7 window, falling back to 5x5.
  std::vector<Subset> subsets;
  for (int r = params.max_radius; r >= params.min_radius; --r) {
    subsets = BorderSubsets(skeleton, candidate, r);
    out.radius = r;
    if (subsets.size() >= 3) break;
  }
  for (const Subset& s : subsets) out.border.push_back(s.best);
  if (subsets.size() < 3) return out;  // a degree-2 point
  out.is_junction = true;

  // Stages 4-5: directions of the paths and the pair that makes the line.
  const cv::Point2d c(candidate.x, candidate.y);
  std::vector<cv::Point2d> dir;
  for (const Subset& s : subsets) dir.push_back(cv::Point2d(s.best.x, s.best.y) - c);
  int best_i = -1, best_j = -1;
  double best_score = 1e9;
  for (size_t i = 0; i < dir.size(); ++i) {
    for (size_t j = i + 1; j < dir.size(); ++j) {
      const double opposite = 180.0 - AngleBetweenDeg(dir[i], dir[j]);
      const double lean = std::max(LeanFromVerticalDeg(dir[i]), LeanFromVerticalDeg(dir[j]));
      if (opposite > params.opposite_tolerance_deg || lean > params.vertical_tolerance_deg)
        continue;
      if ((dir[i].y > 0) == (dir[j].y > 0)) continue;  // one must go up, one down
      const double score = opposite + lean;
      if (score < best_score) {
        best_score = score;
        best_i = static_cast<int>(i);
        best_j = static_cast<int>(j);
      }
    }
  }
  if (best_i < 0) {
    out.attribute = subsets.size() >= 4 ? JunctionAttribute::kCross4 : JunctionAttribute::kCross3;
    return out;
  }
  if (dir[best_i].y > 0) std::swap(best_i, best_j);
  out.top = subsets[best_i].best;
  out.bottom = subsets[best_j].best;
  std::vector<int> sides;
  for (int k = 0; k < static_cast<int>(dir.size()); ++k)
    if (k != best_i && k != best_j) sides.push_back(k);
  if (sides.size() != 1) {
    out.attribute = JunctionAttribute::kCross4;
    return out;
  }
  const cv::Point2d sd = dir[sides[0]];
  if (90.0 - LeanFromVerticalDeg(sd) > params.horizontal_tolerance_deg) {
    out.attribute = JunctionAttribute::kCross3;
    return out;
  }
  out.side = subsets[sides[0]].best;
  out.attribute = AttributeForSegment(side, sd.x);
  // Stages 6-7: the JCP is where the segment's path meets the line's path.
  cv::Point2d jcp;
  const cv::Point2d top(out.top.x, out.top.y), bottom(out.bottom.x, out.bottom.y);
  const cv::Point2d side_px(out.side.x, out.side.y);
  if (Intersect(top, bottom, side_px, c, &jcp) && std::abs(jcp.x - c.x) <= out.radius &&
      std::abs(jcp.y - c.y) <= out.radius)
    out.centre = jcp;
  return out;
}

}  // namespace bsls::interpretation
