#include "bsls/interpretation/corner_extension.h"

#include <algorithm>
#include <cmath>

#include "bsls/interpretation/chain_code.h"

namespace bsls::interpretation {
namespace {

constexpr double kPi = 3.14159265358979323846;

// Degrees a direction leans from vertical.
double LeanDeg(cv::Point2d d) { return std::atan2(std::abs(d.x), std::abs(d.y)) * 180.0 / kPi; }

bool IsSet(const cv::Mat& sk, cv::Point p) {
  return p.x >= 0 && p.y >= 0 && p.x < sk.cols && p.y < sk.rows && sk.at<uchar>(p) != 0;
}

// Draws params.stub pixels from `corner` along `dir` if they touch nothing but
// the corner (`own` pixels) and each other; returns whether it drew them.
bool AddStub(cv::Point corner, cv::Point2d dir, const std::vector<cv::Point>& own,
             const CornerParams& params, cv::Mat& skeleton) {
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
    // Pixels of the corner's own cluster are passed over.
    if (std::find(own.begin(), own.end(), q) != own.end()) continue;
    if (IsSet(skeleton, q)) return false;
    for (int c = 0; c < 8; ++c) {
      const cv::Point r = q + CodeStep(c);
      if (IsSet(skeleton, r) && !near_own(r) && !(!stub.empty() && r == stub.back()) &&
          std::find(own.begin(), own.end(), r) == own.end())
        return false;
    }
    stub.push_back(q);
  }
  if (static_cast<int>(stub.size()) < params.stub) return false;
  for (const cv::Point& q : stub) skeleton.at<uchar>(q) = 255;
  return true;
}

}  // namespace

bool CornerParams::IsValid(std::string* error) const {
  if (leg < 2 || stub < 1 || leg_tolerance_deg <= 0 || leg_tolerance_deg >= 45) {
    if (error) *error = "corner params: leg >= 2, stub >= 1, tolerance in (0, 45) degrees";
    return false;
  }
  return true;
}

// Thesis 5.2.3.3: extending a degree-2 point to degree 3.
std::vector<cv::Point> ExtendCorners(const SkeletonGraph& graph, const CornerParams& params,
                                     cv::Mat& skeleton) {
  std::vector<cv::Point> corners;
  // A corner may also be a small cluster of pixels (a node with two branches).
  for (const SkeletonNode& node : graph.nodes()) {
    if (node.kind != NodeKind::kJunction || node.rotation.size() != 2) continue;
    const cv::Point2d d0 = graph.Departure(node.rotation[0]);
    const cv::Point2d d1 = graph.Departure(node.rotation[1]);
    cv::Point2d line_dir;  // from the corner along the line
    if (LeanDeg(d0) <= params.leg_tolerance_deg && LeanDeg(d1) >= 90 - params.leg_tolerance_deg)
      line_dir = d0;
    else if (LeanDeg(d1) <= params.leg_tolerance_deg && LeanDeg(d0) >= 90 - params.leg_tolerance_deg)
      line_dir = d1;
    else
      continue;
    // The segment must end on a line (a junction), not run off along an outline.
    const int segment = line_dir == d0 ? node.rotation[1] : node.rotation[0];
    if (graph.nodes()[graph.Target(segment)].kind != NodeKind::kJunction) continue;
    const cv::Point corner(cvRound(node.centre.x), cvRound(node.centre.y));
    if (AddStub(corner, -line_dir, node.pixels, params, skeleton)) corners.push_back(corner);
  }
  for (const SkeletonEdge& edge : graph.edges()) {
    const std::vector<cv::Point>& px = edge.pixels;
    const int n = static_cast<int>(px.size());
    int best = -1;
    double best_turn = 0;
    cv::Point2d best_vertical;
    bool segment_after = false;  // the segment leg is the part after the corner
    for (int i = params.leg; i + params.leg < n; ++i) {
      const cv::Point2d in(px[i] - px[i - params.leg]);
      const cv::Point2d out(px[i + params.leg] - px[i]);
      const double lin = LeanDeg(in), lout = LeanDeg(out);
      cv::Point2d vertical_towards_corner;
      bool after;
      if (lin <= params.leg_tolerance_deg && lout >= 90 - params.leg_tolerance_deg) {
        vertical_towards_corner = in;  // from the line into the corner
        after = true;
      } else if (lout <= params.leg_tolerance_deg && lin >= 90 - params.leg_tolerance_deg) {
        vertical_towards_corner = -out;
        after = false;
      } else {
        continue;
      }
      const double turn = std::abs(lin - lout);
      if (turn > best_turn) {
        best_turn = turn;
        best = i;
        best_vertical = vertical_towards_corner;
        segment_after = after;
      }
    }
    if (best < 0) continue;
    // The segment must end on a line (a junction), not run off along an outline.
    const int segment_end = segment_after ? edge.to : edge.from;
    if (graph.nodes()[segment_end].kind != NodeKind::kJunction) continue;
    // The stub goes on along the line, beyond the corner.
    const cv::Point corner = px[best];
    if (!AddStub(corner, best_vertical, {corner}, params, skeleton)) continue;
    corners.push_back(corner);
  }
  return corners;
}

}  // namespace bsls::interpretation
