#include "bsls/interpretation/corner_extension.h"

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
  for (const SkeletonEdge& edge : graph.edges()) {
    const std::vector<cv::Point>& px = edge.pixels;
    const int n = static_cast<int>(px.size());
    int best = -1;
    double best_turn = 0;
    cv::Point2d best_vertical;
    for (int i = params.leg; i + params.leg < n; ++i) {
      const cv::Point2d in(px[i] - px[i - params.leg]);
      const cv::Point2d out(px[i + params.leg] - px[i]);
      const double lin = LeanDeg(in), lout = LeanDeg(out);
      cv::Point2d vertical_towards_corner;
      if (lin <= params.leg_tolerance_deg && lout >= 90 - params.leg_tolerance_deg) {
        vertical_towards_corner = in;  // from the line into the corner
      } else if (lout <= params.leg_tolerance_deg && lin >= 90 - params.leg_tolerance_deg) {
        vertical_towards_corner = -out;
      } else {
        continue;
      }
      const double turn = std::abs(lin - lout);
      if (turn > best_turn) {
        best_turn = turn;
        best = i;
        best_vertical = vertical_towards_corner;
      }
    }
    if (best < 0) continue;
    // The stub goes on along the line, beyond the corner.
    const cv::Point2d dir = best_vertical * (1.0 / std::hypot(best_vertical.x, best_vertical.y));
    const cv::Point corner = px[best];
    std::vector<cv::Point> stub;
    bool clear = true;
    for (int k = 1; k <= params.stub && clear; ++k) {
      const cv::Point q(cvRound(corner.x + k * dir.x), cvRound(corner.y + k * dir.y));
      if (q.x < 0 || q.y < 0 || q.x >= skeleton.cols || q.y >= skeleton.rows || IsSet(skeleton, q)) {
        clear = false;
        break;
      }
      // The stub must not touch other strokes.
      for (int c = 0; c < 8 && clear; ++c) {
        const cv::Point r = q + CodeStep(c);
        if (!IsSet(skeleton, r)) continue;
        const bool own = std::abs(r.x - corner.x) <= 1 && std::abs(r.y - corner.y) <= 1;
        const bool previous = !stub.empty() && r == stub.back();
        if (!own && !previous) clear = false;
      }
      stub.push_back(q);
    }
    if (!clear) continue;
    for (const cv::Point& q : stub) skeleton.at<uchar>(q) = 255;
    corners.push_back(corner);
  }
  return corners;
}

}  // namespace bsls::interpretation
