#include "bsls/interpretation/corner_extension.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "bsls/interpretation/chain_code.h"

namespace bsls::interpretation {
namespace {

// Draws params.stub pixels from `corner` along `dir` if they touch nothing but
// the corner (`own` pixels) and each other; returns whether it drew them.
bool AddStub(cv::Point corner, cv::Point2d dir, const std::vector<cv::Point>& own,
             const CornerParams& params, cv::Mat& skeleton, const cv::Mat& mask) {
  dir *= 1.0 / std::hypot(dir.x, dir.y);
  auto near_own = [&](cv::Point r) {
    for (const cv::Point& o : own)
      if (std::abs(r.x - o.x) <= 1 && std::abs(r.y - o.y) <= 1) return true;
    return false;
  };
  std::vector<cv::Point> stub;
  for (int k = 1; static_cast<int>(stub.size()) < params.stub && k <= params.stub + 4; ++k) {
    const cv::Point q(cvRound(corner.x + k * dir.x), cvRound(corner.y + k * dir.y));
    if (q.x < 0 || q.y < 0 || q.x >= skeleton.cols || q.y >= skeleton.rows) return false;
    // Pixels of the corner's own cluster are passed over, and so is the
    // elbow pixel of a 4-connected corner (the skeleton graph leaves it out).
    if (std::find(own.begin(), own.end(), q) != own.end()) continue;
    if (k == 1 && stub.empty() && IsSetPixel(skeleton, q)) continue;
    if (IsSetPixel(skeleton, q)) return false;
    // The stroke must show in the image beyond the corner.
    if (!mask.empty() && stub.empty() && !IsSetPixel(mask, q)) return false;
    for (int c = 0; c < 8; ++c) {
      const cv::Point r = q + CodeStep(c);
      if (IsSetPixel(skeleton, r) && !near_own(r) && !(!stub.empty() && r == stub.back()) &&
          std::find(own.begin(), own.end(), r) == own.end())
        return false;
    }
    stub.push_back(q);
  }
  if (static_cast<int>(stub.size()) < params.stub) return false;
  for (const cv::Point& q : stub) skeleton.at<uchar>(q) = 255;
  return true;
}

// The row pitch along lines: the median distance between neighbouring
// T-junctions joined by a vertical chain; 0 where there are none.
double RowPitch(const SkeletonGraph& graph, const CornerParams& params) {
  std::vector<double> spacings;
  for (const SkeletonEdge& edge : graph.edges()) {
    if (edge.from < 0 || edge.to < 0 || edge.from == edge.to) continue;
    const SkeletonNode& a = graph.nodes()[edge.from];
    const SkeletonNode& b = graph.nodes()[edge.to];
    if (a.kind != NodeKind::kJunction || b.kind != NodeKind::kJunction || a.rotation.size() != 3 ||
        b.rotation.size() != 3)
      continue;
    const cv::Point2d chord = b.centre - a.centre;
    if (LeanFromVerticalDeg(chord) <= params.leg_tolerance_deg)
      spacings.push_back(std::hypot(chord.x, chord.y));
  }
  double row_pitch = 0.0;
  if (!spacings.empty()) {
    std::nth_element(spacings.begin(), spacings.begin() + spacings.size() / 2, spacings.end());
    row_pitch = spacings[spacings.size() / 2];
  }
  return row_pitch;
}

// What a corner must show before it is extended, judged on one graph.
class CornerJudge {
 public:
  CornerJudge(const SkeletonGraph& graph, const CornerParams& params, const cv::Mat& stripe_mask,
              cv::Rect imaged)
      : graph_(graph),
        params_(params),
        stripe_mask_(stripe_mask),
        imaged_(imaged),
        row_pitch_(RowPitch(graph, params)) {}

  // True when the stub from `corner` along `dir` (from the line into the
  // corner) leaves the imaged area: the line runs out of the frame there.
  bool LineLeavesFrame(cv::Point corner, cv::Point2d dir) const {
    dir *= params_.stub / std::hypot(dir.x, dir.y);
    return !imaged_.contains(cv::Point(cvRound(corner.x + dir.x), cvRound(corner.y + dir.y)));
  }

  // A corner's segment must end on a line (a junction), not run off along an
  // outline; a free end (the partner line too faint to see) counts for a
  // segment long enough not to be a hook (shorter where the line leaves the
  // frame or where the pattern puts the line's next junction), when the
  // mask will vouch for the line going on.
  bool SegmentCounts(NodeKind end, int length, bool at_edge, bool in_pattern) const {
    const int needed = at_edge      ? params_.min_free_segment_at_edge
                       : in_pattern ? params_.min_free_segment_in_pattern
                                    : params_.min_free_segment;
    return end == NodeKind::kJunction || (!stripe_mask_.empty() && length >= needed);
  }

  // True when a corner at `corner`, whose segment leaves towards x sign
  // `segment_dx`, sits where the pattern puts the next junction after
  // `node` (reached from the corner along the line).
  bool InPattern(cv::Point corner, double segment_dx, int node) const {
    if (row_pitch_ <= 0.0 || node < 0) return false;
    const SkeletonNode& t = graph_.nodes()[node];
    if (t.kind != NodeKind::kJunction || t.rotation.size() != 3) return false;
    const double distance = std::hypot(t.centre.x - corner.x, t.centre.y - corner.y);
    if (std::abs(distance - row_pitch_) > params_.pitch_tolerance * row_pitch_) return false;
    int segment = t.rotation[0];
    for (int h : t.rotation)
      if (std::abs(graph_.Departure(h).y) < std::abs(graph_.Departure(segment).y)) segment = h;
    return graph_.Departure(segment).x * segment_dx < 0.0;
  }

 private:
  const SkeletonGraph& graph_;
  const CornerParams& params_;
  const cv::Mat& stripe_mask_;
  const cv::Rect imaged_;
  const double row_pitch_;
};

// A corner may also be a small cluster of pixels (a node with two
// branches): stubs such corners that qualify, adding each to `corners`.
void ExtendClusterCorners(const SkeletonGraph& graph, const CornerParams& params,
                          const CornerJudge& judge, cv::Mat& skeleton, const cv::Mat& stripe_mask,
                          std::vector<cv::Point>* corners) {
  for (const SkeletonNode& node : graph.nodes()) {
    if (node.kind != NodeKind::kJunction || node.rotation.size() != 2) continue;
    const cv::Point2d d0 = graph.Departure(node.rotation[0]);
    const cv::Point2d d1 = graph.Departure(node.rotation[1]);
    cv::Point2d line_dir;  // from the corner along the line
    if (LeanFromVerticalDeg(d0) <= params.leg_tolerance_deg &&
        LeanFromVerticalDeg(d1) >= 90 - params.leg_tolerance_deg)
      line_dir = d0;
    else if (LeanFromVerticalDeg(d1) <= params.leg_tolerance_deg &&
             LeanFromVerticalDeg(d0) >= 90 - params.leg_tolerance_deg)
      line_dir = d1;
    else
      continue;
    const int segment = line_dir == d0 ? node.rotation[1] : node.rotation[0];
    const int line = line_dir == d0 ? node.rotation[0] : node.rotation[1];
    const cv::Point corner(cvRound(node.centre.x), cvRound(node.centre.y));
    if (!judge.SegmentCounts(
            graph.nodes()[graph.Target(segment)].kind, graph.Length(segment),
            judge.LineLeavesFrame(corner, -line_dir),
            judge.InPattern(corner, graph.Departure(segment).x, graph.Target(line))))
      continue;
    if (AddStub(corner, -line_dir, node.pixels, params, skeleton, stripe_mask))
      corners->push_back(corner);
  }
}

// A sharp turn between a vertical and a horizontal leg along a chain.
struct ChainCorner {
  int index;
  double turn;
  cv::Point2d vertical;  // from the line into the corner
  bool segment_after;    // the segment leg follows the corner along the chain
};

// Every sharp turn between a vertical and a horizontal leg along the chain
// `px` (a chain may hold several, e.g. both top corners of a brick whose
// stubs are cut off), the strongest of each run of turning pixels.
std::vector<ChainCorner> SharpTurns(const std::vector<cv::Point>& px, const CornerParams& params) {
  const int n = static_cast<int>(px.size());
  std::vector<ChainCorner> found;
  for (int i = params.leg; i + params.leg < n; ++i) {
    const cv::Point2d in(px[i] - px[i - params.leg]);
    const cv::Point2d out(px[i + params.leg] - px[i]);
    const double lin = LeanFromVerticalDeg(in), lout = LeanFromVerticalDeg(out);
    ChainCorner c{i, std::abs(lin - lout), {}, false};
    if (lin <= params.leg_tolerance_deg && lout >= 90 - params.leg_tolerance_deg) {
      c.vertical = in;
      c.segment_after = true;
    } else if (lout <= params.leg_tolerance_deg && lin >= 90 - params.leg_tolerance_deg) {
      c.vertical = -out;
    } else {
      continue;
    }
    if (!found.empty() && i - found.back().index < params.leg) {
      if (c.turn > found.back().turn) found.back() = c;
    } else {
      found.push_back(c);
    }
  }
  return found;
}

// A rounded corner passes the leg test a few pixels before its apex: the
// corner is the pixel farthest from the chord across the bend (within leg
// pixels of `index` along the chain).
int Apex(const std::vector<cv::Point>& px, int index, int leg) {
  const int n = static_cast<int>(px.size());
  const int lo = std::max(0, index - leg), hi = std::min(n - 1, index + leg);
  const cv::Point2d chord(px[hi] - px[lo]);
  int apex = index;
  double farthest = -1;
  for (int k = lo; k <= hi; ++k) {
    const cv::Point2d r(px[k] - px[lo]);
    const double d = std::abs(chord.x * r.y - chord.y * r.x);
    if (d > farthest) farthest = d, apex = k;
  }
  return apex;
}

// Stubs the corners along one chain that qualify, adding each to `corners`.
void ExtendChainCorners(const SkeletonGraph& graph, const SkeletonEdge& edge,
                        const CornerParams& params, const CornerJudge& judge, cv::Mat& skeleton,
                        const cv::Mat& stripe_mask, std::vector<cv::Point>* corners) {
  const std::vector<cv::Point>& px = edge.pixels;
  const int n = static_cast<int>(px.size());
  // True when the chain, walked from index i in direction step, leaves the
  // horizontal (turns into a line) before it ends, or its end counts.
  auto segment_ends_on_line = [&](int i, int step, bool at_edge, bool pattern) {
    for (int k = i + step * params.leg; k >= 0 && k < n; k += step) {
      const cv::Point2d d(px[k] - px[k - step * params.leg]);
      if (LeanFromVerticalDeg(d) < 90 - params.leg_tolerance_deg) return true;
    }
    const int end = step > 0 ? edge.to : edge.from;
    return judge.SegmentCounts(graph.nodes()[end].kind, step > 0 ? n - 1 - i : i, at_edge, pattern);
  };
  for (const ChainCorner& c : SharpTurns(px, params)) {
    const int step = c.segment_after ? 1 : -1;
    const double segment_dx =
        px[std::clamp(c.index + step * params.leg, 0, n - 1)].x - px[c.index].x;
    const int line_end = c.segment_after ? edge.from : edge.to;
    const bool pattern = judge.InPattern(px[c.index], segment_dx, line_end);
    if (!segment_ends_on_line(c.index, step, judge.LineLeavesFrame(px[c.index], c.vertical),
                              pattern))
      continue;
    const int apex = Apex(px, c.index, params.leg);
    const cv::Point corner = px[apex];
    // Where the pattern puts a junction, the chain's pixels next to the
    // apex count as the corner's own: a line meeting its segment at a
    // sharp angle (the chin's bottom row) has the segment's first pixel
    // beside the stub's first. Elsewhere a stub touching them would join
    // strokes the pattern does not (whole stretches then take wrong rows).
    std::vector<cv::Point> own{corner};
    if (pattern)
      for (int k = std::max(0, apex - 2); k <= std::min(n - 1, apex + 2); ++k)
        if (k != apex) own.push_back(px[k]);
    if (AddStub(corner, c.vertical, own, params, skeleton, stripe_mask)) corners->push_back(corner);
  }
}

}  // namespace

bool CornerParams::IsValid(std::string* error) const {
  if (leg < 2 || stub < 1 || leg_tolerance_deg <= 0 || leg_tolerance_deg >= 45 ||
      min_free_segment < 1 || min_free_segment_at_edge < 1 || min_free_segment_in_pattern < 1 ||
      !(pitch_tolerance > 0 && pitch_tolerance < 1)) {
    if (error)
      *error =
          "corner params: leg >= 2, stub >= 1, min_free_segment(_at_edge, _in_pattern) >= 1, "
          "tolerance in (0, 45) degrees, pitch_tolerance in (0, 1)";
    return false;
  }
  return true;
}

// Thesis 5.2.3.3: extending a degree-2 point to degree 3.
std::vector<cv::Point> ExtendCorners(const SkeletonGraph& graph, const CornerParams& params,
                                     cv::Mat& skeleton, const cv::Mat& stripe_mask,
                                     cv::Rect imaged) {
  if (!stripe_mask.empty() &&
      (stripe_mask.type() != CV_8UC1 || stripe_mask.size() != skeleton.size()))
    throw std::invalid_argument(
        "ExtendCorners: stripe mask must be CV_8UC1 of the skeleton's size");
  std::vector<cv::Point> corners;
  if (imaged.empty()) imaged = cv::Rect(0, 0, skeleton.cols, skeleton.rows);
  const CornerJudge judge(graph, params, stripe_mask, imaged);
  ExtendClusterCorners(graph, params, judge, skeleton, stripe_mask, &corners);
  for (const SkeletonEdge& edge : graph.edges())
    ExtendChainCorners(graph, edge, params, judge, skeleton, stripe_mask, &corners);
  return corners;
}

}  // namespace bsls::interpretation
