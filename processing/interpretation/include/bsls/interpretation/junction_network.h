// The skeleton graph read as the brick pattern: every junction node gets its
// thesis attribute (5.2.3.1) and the half-edges that continue its line upwards
// and downwards and its segment sideways, so that lines and segments can be
// followed from junction to junction.
//
// Image coordinates: x right, y down.
#ifndef BSLS_INTERPRETATION_JUNCTION_NETWORK_H_
#define BSLS_INTERPRETATION_JUNCTION_NETWORK_H_

#include <optional>
#include <vector>

#include "bsls/interpretation/junction_detect.h"
#include "bsls/interpretation/skeleton_graph.h"
#include "bsls/pattern/brick_pattern.h"

namespace bsls::interpretation {

struct NodeRole {
  // For junction nodes: the attribute; for ends and anchors: unset.
  std::optional<JunctionAttribute> attribute;
  int up = -1;         // half-edge continuing the line upwards (smaller y), or -1
  int down = -1;       // half-edge continuing the line downwards, or -1
  int side = -1;       // half-edge of the segment, or -1
  cv::Point2d centre;  // junction centre point (JCP) or end pixel
};

// One step along a line or a segment, from one node to the next.
struct Step {
  int half_edge = -1;  // the half-edge walked
  int target = -1;     // node reached
  // How the step arrived: true when it entered the target through the
  // target's opposite line branch (a line continues) or, for a segment,
  // through the target's segment branch.
  bool consistent = false;
};

class JunctionNetwork {
 public:
  // Classifies every node of `graph` for the brick slide of `side`, using the
  // departure directions of its half-edges (thesis 5.2.3.1, stages 4-6).
  JunctionNetwork(const SkeletonGraph& graph, pattern::Side side,
                  const JunctionParams& params = {});

  const SkeletonGraph& graph() const { return graph_; }
  pattern::Side side() const { return side_; }
  const NodeRole& role(int node) const { return roles_[node]; }
  // True for nodes that are T-junctions of the pattern (direct or corresponding).
  bool IsPatternJunction(int node) const;

  // The next node along the line from `node`, downwards or upwards; nullopt
  // when the node has no such branch.
  std::optional<Step> AlongLine(int node, bool downwards) const;
  // The node at the far end of the node's segment; nullopt without a segment.
  std::optional<Step> AcrossSegment(int node) const;
  // True when a half-edge runs more vertically than horizontally overall.
  bool IsVertical(int half_edge) const;

 private:
  const SkeletonGraph& graph_;
  pattern::Side side_;
  std::vector<NodeRole> roles_;
};

}  // namespace bsls::interpretation

#endif  // BSLS_INTERPRETATION_JUNCTION_NETWORK_H_
