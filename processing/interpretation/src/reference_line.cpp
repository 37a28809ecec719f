#include "bsls/interpretation/reference_line.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "bsls/interpretation/chain_code.h"
#include "bsls/interpretation/line_fill.h"

namespace bsls::interpretation {
namespace {

cv::Point2d Normalised(cv::Point2d d) {
  const double n = std::hypot(d.x, d.y);
  return n > 1e-9 ? d * (1.0 / n) : cv::Point2d(0, 0);
}

// Thesis Figure 5.4: the moving vertical line sweeps in from the inner side
// (where nothing is lit) and stops on the first lit pixel of the central rows.
bool FindOverlap(const cv::Mat& sk, pattern::Side side, const ReferenceLineParams& params,
                 cv::Point* overlap) {
  const int inward = -pattern::ImageDirectionOfIncreasingP(side);  // +1: line 0 is right-most
  const int band = static_cast<int>(sk.rows * params.central_band / 2.0);
  const int centre = sk.rows / 2;
  std::vector<std::pair<int, int>> first;  // (row, x of the inner-most lit pixel)
  for (int y = std::max(0, centre - band); y < std::min(sk.rows, centre + band); ++y) {
    const uchar* row = sk.ptr<uchar>(y);
    if (inward > 0) {
      for (int x = sk.cols - 1; x >= 0; --x)
        if (row[x]) {
          first.push_back({y, x});
          break;
        }
    } else {
      for (int x = 0; x < sk.cols; ++x)
        if (row[x]) {
          first.push_back({y, x});
          break;
        }
    }
  }
  if (first.empty()) return false;
  // The moving line stops where most rows agree: the median inner-most column.
  std::vector<int> xs;
  for (const auto& f : first) xs.push_back(f.second);
  std::nth_element(xs.begin(), xs.begin() + xs.size() / 2, xs.end());
  const int moving_x = xs[xs.size() / 2];
  // The overlap point: the row nearest the centre whose inner-most pixel lies
  // on the moving line and continues vertically.
  std::sort(first.begin(), first.end(), [&](const auto& a, const auto& b) {
    return std::abs(a.first - centre) < std::abs(b.first - centre);
  });
  for (const auto& [y, x] : first) {
    if (std::abs(x - moving_x) > params.start_tolerance) continue;
    int vertical = 0;
    for (int dy : {-2, -1, 1, 2})
      for (int dx = -2; dx <= 2; ++dx)
        if (IsSetPixel(sk, {x + dx, y + dy})) {
          ++vertical;
          break;
        }
    if (vertical >= 3) {
      *overlap = {x, y};
      return true;
    }
  }
  return false;
}

class Tracer {
 public:
  Tracer(cv::Mat& sk, const ReferenceLineParams& params, pattern::Side side)
      : sk_(sk),
        params_(params),
        visited_(sk.size(), CV_8UC1, cv::Scalar(0)),
        inward_(-pattern::ImageDirectionOfIncreasingP(side)) {}

  void MarkVisited(cv::Point p) { visited_.at<uchar>(p) = 1; }

  // Follows the line from `start` in vertical direction `sign` (+1 down, -1 up).
  std::vector<cv::Point> Follow(cv::Point start, int sign,
                                std::vector<std::pair<cv::Point, cv::Point>>* fills) {
    std::vector<cv::Point> path{start};
    cv::Point2d dir(0, sign);
    while (true) {
      const cv::Point p = path.back();
      cv::Point next;
      if (NextNeighbour(p, dir, &next)) {
        path.push_back(next);
        MarkVisited(next);
      } else if (ScanAreas(p, dir, &next)) {
        // Thesis 5.2.2: seal the gap, then carry on from the pixel found.
        fills->push_back({p, next});
        std::vector<cv::Point> gap = BresenhamLine(p, next);
        for (size_t i = 1; i < gap.size(); ++i) {
          sk_.at<uchar>(gap[i]) = 255;
          path.push_back(gap[i]);
          MarkVisited(gap[i]);
        }
      } else {
        break;
      }
      const size_t back = std::min<size_t>(path.size() - 1, params_.direction_memory);
      const cv::Point2d d = Normalised(cv::Point2d(path.back() - path[path.size() - 1 - back]));
      // Keep the trace heading along the line: never turn past horizontal.
      if (d.y * sign > 0.35) dir = d;
    }
    return path;
  }

 private:
  // Scan area 1 (the eight neighbours), ranked by how straight the line goes on.
  bool NextNeighbour(cv::Point p, cv::Point2d dir, cv::Point* next) {
    double best = 0.3;
    bool found = false;
    for (int c = 0; c < 8; ++c) {
      const cv::Point q = p + CodeStep(c);
      if (!IsSetPixel(sk_, q) || visited_.at<uchar>(q)) continue;
      const cv::Point2d step = Normalised(cv::Point2d(CodeStep(c)));
      if (step.x * dir.x + step.y * dir.y <= 0.2) continue;
      const cv::Point2d ahead = Normalised(cv::Point2d(Lookahead(q, p) - p));
      // Ties go to the inner side: branches of line 0 leave outwards.
      const double score = ahead.x * dir.x + ahead.y * dir.y + 1e-3 * inward_ * (q.x - p.x);
      if (score > best) {
        best = score;
        *next = q;
        found = true;
      }
    }
    return found;
  }

  // Where a greedy walk of `lookahead` pixels from q (not back to p) ends.
  cv::Point Lookahead(cv::Point q, cv::Point p) const {
    cv::Point prev = p, cur = q;
    for (int i = 0; i < params_.lookahead; ++i) {
      cv::Point best_next = cur;
      double best = -2.0;
      const cv::Point2d heading = Normalised(cv::Point2d(cur - prev));
      for (int c = 0; c < 8; ++c) {
        const cv::Point r = cur + CodeStep(c);
        if (r == prev || r == p || !IsSetPixel(sk_, r)) continue;
        const cv::Point2d s = Normalised(cv::Point2d(CodeStep(c)));
        const double score = s.x * heading.x + s.y * heading.y;
        if (score > best) {
          best = score;
          best_next = r;
        }
      }
      if (best_next == cur) break;
      prev = cur;
      cur = best_next;
    }
    return cur;
  }

  // Scan areas 2 and 3 (thesis Figures 5.7-5.8): a cone ahead of the line,
  // then the whole half of the 15x15 area ahead.
  bool ScanAreas(cv::Point p, cv::Point2d dir, cv::Point* next) const {
    const int half = params_.scan_area / 2;
    double best_cone = 1e9, best_wide = 1e9;
    cv::Point cone_hit, wide_hit;
    for (int dy = -half; dy <= half; ++dy) {
      for (int dx = -half; dx <= half; ++dx) {
        const cv::Point q(p.x + dx, p.y + dy);
        if (!IsSetPixel(sk_, q) || visited_.at<uchar>(q)) continue;
        const double along = dx * dir.x + dy * dir.y;
        const double across = std::abs(dx * dir.y - dy * dir.x);
        if (along < 1.5) continue;
        const double score = along + 2.0 * across;
        if (across <= params_.cone_slope * along + 1.0) {
          if (score < best_cone) {
            best_cone = score;
            cone_hit = q;
          }
        } else if (score < best_wide) {
          best_wide = score;
          wide_hit = q;
        }
      }
    }
    if (best_cone < 1e9) {
      *next = cone_hit;
      return true;
    }
    if (best_wide < 1e9) {
      *next = wide_hit;
      return true;
    }
    return false;
  }

  cv::Mat& sk_;
  const ReferenceLineParams& params_;
  cv::Mat visited_;
  int inward_;
};

}  // namespace

bool ReferenceLineParams::IsValid(std::string* error) const {
  auto fail = [error](const char* why) {
    if (error) *error = why;
    return false;
  };
  if (scan_area < 3 || scan_area > 101 || scan_area % 2 == 0)
    return fail("scan_area must be an odd number of pixels in 3..101");
  if (cone_slope <= 0.0 || cone_slope > 5.0) return fail("cone_slope must lie in (0, 5]");
  if (direction_memory < 1 || lookahead < 0) return fail("direction_memory >= 1, lookahead >= 0");
  if (central_band <= 0.0 || central_band > 1.0) return fail("central_band must lie in (0, 1]");
  if (min_length < 2) return fail("min_length must be at least 2 pixels");
  return true;
}

// Thesis 5.2.1: reference line tracing.
bool TraceReferenceLine(cv::Mat& skeleton, pattern::Side side, const ReferenceLineParams& params,
                        ReferenceLine* line, std::string* why) {
  if (skeleton.empty() || skeleton.type() != CV_8UC1)
    throw std::invalid_argument("TraceReferenceLine: skeleton must be a non-empty CV_8UC1 image");
  std::string invalid;
  if (!params.IsValid(&invalid)) throw std::invalid_argument("TraceReferenceLine: " + invalid);

  cv::Point overlap;
  if (!FindOverlap(skeleton, side, params, &overlap)) {
    if (why) *why = "no lit vertical line crosses the central rows";
    return false;
  }
  cv::Mat work = skeleton.clone();
  Tracer tracer(work, params, side);
  tracer.MarkVisited(overlap);
  ReferenceLine result;
  result.overlap = overlap;
  std::vector<std::pair<cv::Point, cv::Point>> fills;
  std::vector<cv::Point> up = tracer.Follow(overlap, -1, &fills);
  std::vector<cv::Point> down = tracer.Follow(overlap, +1, &fills);
  result.pixels.assign(up.rbegin(), up.rend());
  result.pixels.insert(result.pixels.end(), down.begin() + 1, down.end());
  const int extent = result.pixels.back().y - result.pixels.front().y;
  if (extent < params.min_length) {
    if (why)
      *why = "the line found at column " + std::to_string(overlap.x) + " spans only " +
             std::to_string(extent) + " rows";
    return false;
  }
  result.fills = std::move(fills);
  skeleton = work;
  *line = std::move(result);
  return true;
}

}  // namespace bsls::interpretation
