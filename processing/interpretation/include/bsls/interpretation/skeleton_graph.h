// The one-pixel skeleton as a plane graph: nodes are junction clusters and
// line ends, edges are the pixel chains between them, and faces are the
// closed walks that the thesis's boundary tracing (5.2.3) and loop tracing
// (5.1.4) follow around the image components.
//
// Image coordinates: x to the right, y downwards, pixel (x, y) at column x,
// row y. Angles are measured anticlockwise as seen on the screen (y up).
//
// A half-edge is one direction of an edge: edge e has half-edges 2e (from
// `from` to `to`) and 2e + 1 (back). Each node keeps its outgoing half-edges
// in anticlockwise order; the face walk turns to the next half-edge clockwise
// after arriving, so every face is walked with its inside on the left
// (screen), and the outside of the whole pattern is walked clockwise.
//
// Thread-safety: a built graph is immutable; const members are safe to share.
#ifndef BSLS_INTERPRETATION_SKELETON_GRAPH_H_
#define BSLS_INTERPRETATION_SKELETON_GRAPH_H_

#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "bsls/common/cancellation.h"

namespace bsls::interpretation {

struct GraphParams {
  // Pixels along a chain used to measure the direction in which it leaves a node.
  int departure_probe = 6;

  // True when the numbers are usable; otherwise says why.
  bool IsValid(std::string* error) const;
};

enum class NodeKind {
  kJunction,  // a cluster of pixels with three or more neighbours
  kEnd,       // a pixel with one neighbour (thesis: end point)
  kAnchor,    // a pixel chosen on a closed chain that has no other node
};

struct SkeletonNode {
  NodeKind kind = NodeKind::kEnd;
  std::vector<cv::Point> pixels;  // the cluster (one pixel for ends and anchors)
  cv::Point2d centre;             // mean of the pixels
  std::vector<int> rotation;      // outgoing half-edges, anticlockwise
};

struct SkeletonEdge {
  int from = -1;
  int to = -1;
  std::vector<cv::Point> pixels;  // chain pixels in order from `from` to `to`, nodes excluded
};

class SkeletonGraph {
 public:
  // Builds the graph of a CV_8UC1 skeleton (non-zero = line); isolated pixels
  // are ignored. Throws std::invalid_argument for an empty or non-8-bit image
  // and Cancelled when `cancel` asks (between the build's steps).
  static SkeletonGraph Build(const cv::Mat& skeleton, const GraphParams& params = {},
                             const Cancellation& cancel = {});

  const std::vector<SkeletonNode>& nodes() const { return nodes_; }
  const std::vector<SkeletonEdge>& edges() const { return edges_; }
  cv::Size size() const { return size_; }
  int HalfEdgeCount() const { return static_cast<int>(edges_.size()) * 2; }

  static int Twin(int half_edge) { return half_edge ^ 1; }
  static int EdgeOf(int half_edge) { return half_edge >> 1; }
  // Node a half-edge leaves from.
  int Origin(int half_edge) const;
  // Node a half-edge arrives at.
  int Target(int half_edge) const;
  // Unit vector in which a half-edge leaves its origin (image axes).
  cv::Point2d Departure(int half_edge) const { return departure_[half_edge]; }
  // Chain pixels of a half-edge in walking order (nodes excluded).
  std::vector<cv::Point> Pixels(int half_edge) const;
  // Number of chain pixels of a half-edge.
  int Length(int half_edge) const {
    return static_cast<int>(edges_[EdgeOf(half_edge)].pixels.size());
  }
  // Degree of a node: the number of half-edges leaving it.
  int Degree(int node) const { return static_cast<int>(nodes_[node].rotation.size()); }

  // The half-edge that follows `half_edge` in its face walk.
  int NextInFace(int half_edge) const;
  // Every face walk, each a cyclic sequence of half-edges; every half-edge is
  // in exactly one walk.
  std::vector<std::vector<int>> Faces() const;
  // Twice the signed area enclosed by a face walk (positive = anticlockwise on screen).
  double SignedArea2(const std::vector<int>& face) const;

  // Node owning a pixel, or -1.
  int NodeAt(cv::Point p) const;
  // Edge whose chain holds a pixel, or -1.
  int EdgeAt(cv::Point p) const;

 private:
  class Builder;  // the steps of Build (skeleton_graph.cpp)

  cv::Size size_;
  std::vector<SkeletonNode> nodes_;
  std::vector<SkeletonEdge> edges_;
  std::vector<cv::Point2d> departure_;
  std::vector<int> rotation_index_;  // position of each half-edge in its origin's rotation
  cv::Mat owner_;                    // CV_32S: node id, -(edge id) - 2, or -1
};

}  // namespace bsls::interpretation

#endif  // BSLS_INTERPRETATION_SKELETON_GRAPH_H_
