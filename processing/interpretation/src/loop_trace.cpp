#include "bsls/interpretation/loop_trace.h"

#include <algorithm>
#include <map>

namespace bsls::interpretation {

std::string_view ToString(LoopClass c) {
  switch (c) {
    case LoopClass::kComplete:
      return "complete";
    case LoopClass::kBoundary:
      return "boundary";
    case LoopClass::kOneDiscontinuity:
      return "one_discontinuity";
    case LoopClass::kDoubleDiscontinuity:
      return "double_discontinuity";
    case LoopClass::kMissingJunction:
      return "missing_junction";
    case LoopClass::kTwoMissingJunctions:
      return "two_missing_junctions";
    case LoopClass::kLargeArea:
      return "large_area";
    case LoopClass::kOverlap:
      return "overlap";
    case LoopClass::kIncomplete:
      return "incomplete";
  }
  return "?";
}

std::vector<LoopEvent> LoopRecord::Ends() const {
  std::vector<LoopEvent> ends;
  for (const LoopEvent& e : events)
    if (e.is_end) ends.push_back(e);
  return ends;
}

// Thesis 5.1.4.1: loop tracing by inverse directional coding, and 5.1.4.2:
// the loop network, DCS and JS.
LoopRecord TraceLoop(const JunctionNetwork& network, const std::vector<int>& face) {
  const SkeletonGraph& g = network.graph();
  LoopRecord r;
  r.walk = face;
  r.area2 = g.SignedArea2(face);
  std::vector<int> visited;  // the junctions met so far (a walk meets a handful)
  // DCS over the walk's pixels, step by step; steps that are not unit moves
  // (node centres of clusters) are skipped.
  std::vector<int> codes;
  bool started = false;
  cv::Point last;
  auto walk_to = [&](const cv::Point& q) {
    if (started) {
      const cv::Point d = q - last;
      const int c = DirectionCode(d.x, d.y);
      if (c >= 0) codes.push_back(InverseCode(c));
    }
    started = true;
    last = q;
  };
  for (int i = 0; i < static_cast<int>(face.size()); ++i) {
    const int h = face[i];
    const std::vector<cv::Point>& chain = g.edges()[SkeletonGraph::EdgeOf(h)].pixels;
    if (h & 1)  // walked backwards
      for (auto it = chain.rbegin(); it != chain.rend(); ++it) walk_to(*it);
    else
      for (const cv::Point& q : chain) walk_to(q);
    const int node = g.Target(h);
    const SkeletonNode& n = g.nodes()[node];
    const NodeRole& role = network.role(node);
    walk_to(cv::Point(cvRound(role.centre.x), cvRound(role.centre.y)));
    if (n.kind == NodeKind::kEnd) {
      LoopEvent e;
      e.is_end = true;
      e.node = node;
      // The piece leaves the end along its only half-edge.
      const cv::Point2d d = g.Departure(SkeletonGraph::Twin(h));
      e.end = ClassifyEnd(d.x, d.y);
      e.position = n.centre;
      e.walk_index = i;
      r.events.push_back(e);
      ++r.n_e;
    } else if (n.kind == NodeKind::kJunction) {
      LoopEvent e;
      e.node = node;
      e.attribute = role.attribute.value_or(JunctionAttribute::kCross3);
      e.position = role.centre;
      e.walk_index = i;
      r.events.push_back(e);
      ++r.n_t;
      if (std::find(visited.begin(), visited.end(), node) != visited.end())
        ++r.repeated;
      else
        visited.push_back(node);
      if (!IsPatternJunction(e.attribute)) ++r.crossings;
    }
  }
  r.dcs = DifferenceCodes(codes);
  ClassifyLoop(r);
  return r;
}

LoopClass ClassifyLoop(LoopRecord& r) {
  if (r.area2 < 0) return r.cls = LoopClass::kBoundary;
  if (r.crossings > 0) return r.cls = LoopClass::kOverlap;
  // Junction kinds must alternate along the JS (T - T' - T - T' ...), except
  // across line 0 where two direct junctions follow each other.
  int breaks = 0;
  std::vector<JunctionAttribute> js;
  for (const LoopEvent& e : r.events)
    if (!e.is_end) js.push_back(e.attribute);
  for (size_t i = 0; i + 1 < js.size(); ++i)
    if (js[i] == js[i + 1]) ++breaks;
  if (r.n_e == 0) {
    const bool brick6 = r.n_t == 6 && breaks == 0;
    const bool brick5 = r.n_t == 5 && breaks <= 1;  // loops on line 0
    if ((brick6 || brick5) && r.repeated == 0) return r.cls = LoopClass::kComplete;
    return r.cls = (breaks > 1 ? LoopClass::kOverlap : LoopClass::kIncomplete);
  }
  int horizontal = 0;
  for (const LoopEvent& e : r.events)
    if (e.is_end && (e.end == EndDirection::kLeft || e.end == EndDirection::kRight)) ++horizontal;
  switch (r.n_e) {
    case 1:
      return r.cls = LoopClass::kIncomplete;
    case 2:
      return r.cls = LoopClass::kOneDiscontinuity;
    case 3:
      return r.cls = LoopClass::kMissingJunction;
    case 4: {
      // Figure 5.34: a double break cuts a junction loose, so the walk passes
      // it three times; two missing junctions (Figure 5.36) leave two line
      // gaps and no such junction.
      std::map<int, int> visits;
      int most = 0;
      for (const LoopEvent& e : r.events)
        if (!e.is_end) most = std::max(most, ++visits[e.node]);
      return r.cls = (horizontal == 0 && most < 3) ? LoopClass::kTwoMissingJunctions
                                                   : LoopClass::kDoubleDiscontinuity;
    }
    default:
      return r.cls = LoopClass::kLargeArea;
  }
}

std::vector<LoopRecord> TraceLoops(const JunctionNetwork& network) {
  std::vector<LoopRecord> out;
  for (const std::vector<int>& face : network.graph().Faces())
    out.push_back(TraceLoop(network, face));
  return out;
}

}  // namespace bsls::interpretation
