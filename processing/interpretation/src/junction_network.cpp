#include "bsls/interpretation/junction_network.h"

#include <algorithm>
#include <cmath>

#include "bsls/interpretation/chain_code.h"

namespace bsls::interpretation {

JunctionNetwork::JunctionNetwork(const SkeletonGraph& graph, pattern::Side side,
                                 const JunctionParams& params)
    : graph_(graph), side_(side), roles_(graph.nodes().size()) {
  for (int n = 0; n < static_cast<int>(graph.nodes().size()); ++n) {
    const SkeletonNode& node = graph.nodes()[n];
    NodeRole& role = roles_[n];
    role.centre = node.centre;
    const std::vector<int>& rot = node.rotation;
    if (node.kind != NodeKind::kJunction || rot.size() < 3) {
      // Ends and anchors: a lone branch continues the line if it is vertical.
      for (int h : rot) {
        const cv::Point2d d = graph.Departure(h);
        if (LeanFromVerticalDeg(d) <= params.vertical_tolerance_deg) {
          (d.y > 0 ? role.down : role.up) = h;
        } else if (rot.size() == 1) {
          role.side = h;
        }
      }
      continue;
    }
    // Thesis 5.2.3.1 stages 4-5: of three branches the most horizontal is the
    // segment, and the other two must leave upwards and downwards (the line,
    // which may bend sharply where the surface folds, e.g. at the lips).
    int best_up = -1, best_down = -1;
    if (rot.size() == 3) {
      int segment = rot[0];
      for (int h : rot)
        if (std::abs(graph.Departure(h).y) < std::abs(graph.Departure(segment).y)) segment = h;
      for (int h : rot) {
        if (h == segment) continue;
        const cv::Point2d d = graph.Departure(h);
        if (LeanFromVerticalDeg(d) > params.vertical_tolerance_deg) continue;
        (d.y < 0 ? best_up : best_down) = h;
      }
      if (best_up >= 0 && best_down >= 0 &&
          180.0 - AngleBetweenDeg(graph.Departure(best_up), graph.Departure(best_down)) >
              params.opposite_tolerance_deg)
        best_up = best_down = -1;
    } else {
      // Four or more branches: a crossing; keep the straightest vertical pair
      // so lines can be followed through it (thesis 5.1.4.8).
      double best_score = 1e9;
      for (int a : rot) {
        for (int b : rot) {
          const cv::Point2d da = graph.Departure(a), db = graph.Departure(b);
          if (a == b || !(da.y < 0 && db.y > 0)) continue;
          const double opposite = 180.0 - AngleBetweenDeg(da, db);
          const double lean = std::max(LeanFromVerticalDeg(da), LeanFromVerticalDeg(db));
          if (opposite > params.opposite_tolerance_deg || lean > params.vertical_tolerance_deg)
            continue;
          if (opposite + lean < best_score) {
            best_score = opposite + lean;
            best_up = a;
            best_down = b;
          }
        }
      }
    }
    if (best_up < 0 || best_down < 0) {
      role.attribute = rot.size() >= 4 ? JunctionAttribute::kCross4 : JunctionAttribute::kCross3;
      continue;
    }
    role.up = best_up;
    role.down = best_down;
    std::vector<int> others;
    for (int h : rot)
      if (h != best_up && h != best_down) others.push_back(h);
    if (others.size() != 1) {
      role.attribute = JunctionAttribute::kCross4;
      continue;
    }
    const cv::Point2d sd = graph.Departure(others[0]);
    if (90.0 - LeanFromVerticalDeg(sd) > params.horizontal_tolerance_deg) {
      role.attribute = JunctionAttribute::kCross3;
      continue;
    }
    role.side = others[0];
    role.attribute = AttributeForSegment(side, sd.x);
  }
  // Thesis 5.1.4.8: where a line comes out from behind a fold beside its
  // neighbour, its end merges into the neighbour's strand in a Y that reads
  // as a junction, the neighbour's short way on to its next junction taken
  // for the segment. That junction knows better: it has a segment of its
  // own and takes the edge for its line. The Y is then a crossing point on
  // the neighbour's line (up, and down through the edge), and the emerging
  // line ends at it.
  std::vector<std::pair<int, int>> merges;  // (node, half-edge its line continues along)
  for (int n = 0; n < static_cast<int>(roles_.size()); ++n) {
    const NodeRole& role = roles_[n];
    if (role.side < 0 || !IsPatternJunction(n) || role.up < 0 || role.down < 0) continue;
    if (graph.Length(role.side) > params.max_merge_edge) continue;
    const int t = graph.Target(role.side);
    const int back = SkeletonGraph::Twin(role.side);
    if (t == n || !IsPatternJunction(t) || roles_[t].side < 0) continue;
    if (roles_[t].up == back || roles_[t].down == back) merges.emplace_back(n, role.side);
  }
  for (const auto& [n, h] : merges) {
    NodeRole& role = roles_[n];
    const bool edge_goes_down = roles_[graph.Target(h)].up == SkeletonGraph::Twin(h);
    (edge_goes_down ? role.down : role.up) = h;
    role.side = -1;
    role.attribute = JunctionAttribute::kCross3;
  }
}

bool JunctionNetwork::IsPatternJunction(int node) const {
  const auto& a = roles_[node].attribute;
  return a.has_value() && interpretation::IsPatternJunction(*a);
}

std::optional<Step> JunctionNetwork::AlongLine(int node, bool downwards) const {
  const int h = downwards ? roles_[node].down : roles_[node].up;
  if (h < 0) return std::nullopt;
  Step step;
  step.half_edge = h;
  step.target = graph_.Target(h);
  const int back = SkeletonGraph::Twin(h);
  const NodeRole& t = roles_[step.target];
  step.consistent = downwards ? (t.up == back) : (t.down == back);
  return step;
}

std::optional<Step> JunctionNetwork::AcrossSegment(int node) const {
  const int h = roles_[node].side;
  if (h < 0) return std::nullopt;
  Step step;
  step.half_edge = h;
  step.target = graph_.Target(h);
  step.consistent = roles_[step.target].side == SkeletonGraph::Twin(h);
  return step;
}

bool JunctionNetwork::IsVertical(int half_edge) const {
  const cv::Point2d a = graph_.nodes()[graph_.Origin(half_edge)].centre;
  const cv::Point2d b = graph_.nodes()[graph_.Target(half_edge)].centre;
  if (graph_.Origin(half_edge) == graph_.Target(half_edge)) return false;
  return std::abs(b.y - a.y) > std::abs(b.x - a.x);
}

}  // namespace bsls::interpretation
