#include "bsls/interpretation/repair.h"

#include <algorithm>
#include <cmath>
#include <set>

#include "bsls/interpretation/line_fill.h"

namespace bsls::interpretation {
namespace {

struct EndInfo {
  int node = -1;
  cv::Point pixel;
  cv::Point2d onward;  // unit direction in which the missing part continues
  EndDirection end = EndDirection::kTop;
  LoopClass loop_class = LoopClass::kIncomplete;
};

struct Candidate {
  double cost = 0;
  int a = -1, b = -1;  // indices into the ends
  RepairKind kind = RepairKind::kLineGap;
};

// Sideways distance of `target` from the ray (origin, dir); negative `along`
// means the target lies behind the ray.
void RayMiss(cv::Point2d origin, cv::Point2d dir, cv::Point2d target, double* along, double* miss) {
  const cv::Point2d d = target - origin;
  *along = d.x * dir.x + d.y * dir.y;
  *miss = std::abs(d.x * dir.y - d.y * dir.x);
}

// True when the Bresenham chord from a to b runs over no skeleton pixel other
// than those within one pixel of its two ends, and slips through no diagonal.
bool ChordIsClear(const cv::Mat& sk, cv::Point a, cv::Point b) {
  const std::vector<cv::Point> chord = BresenhamLine(a, b);
  auto near_end = [&](cv::Point p) {
    return (std::abs(p.x - a.x) <= 1 && std::abs(p.y - a.y) <= 1) ||
           (std::abs(p.x - b.x) <= 1 && std::abs(p.y - b.y) <= 1);
  };
  for (size_t i = 0; i < chord.size(); ++i) {
    const cv::Point p = chord[i];
    if (!near_end(p) && IsSetPixel(sk, p)) return false;
    if (i + 1 < chord.size()) {
      const cv::Point q = chord[i + 1];
      if (p.x != q.x && p.y != q.y) {
        const cv::Point c1(p.x, q.y), c2(q.x, p.y);
        if (!near_end(c1) && !near_end(c2) && IsSetPixel(sk, c1) && IsSetPixel(sk, c2))
          return false;
      }
    }
  }
  return true;
}

// Marches from an end along `onward` for up to `reach` pixels and returns the
// first skeleton pixel met that is not part of the end's own piece.
bool Reach(const cv::Mat& sk, const SkeletonGraph& g, const EndInfo& e, double reach,
           cv::Point* hit) {
  const int own_edge = SkeletonGraph::EdgeOf(g.nodes()[e.node].rotation.front());
  const cv::Point far(cvRound(e.pixel.x + reach * e.onward.x),
                      cvRound(e.pixel.y + reach * e.onward.y));
  const std::vector<cv::Point> ray = BresenhamLine(e.pixel, far);
  auto own = [&](cv::Point p) {
    return g.NodeAt(p) == e.node || g.EdgeAt(p) == own_edge ||
           (std::abs(p.x - e.pixel.x) <= 1 && std::abs(p.y - e.pixel.y) <= 1);
  };
  for (size_t i = 1; i < ray.size(); ++i) {
    const cv::Point p = ray[i];
    if (IsSetPixel(sk, p) && !own(p)) {
      *hit = p;
      return true;
    }
    const cv::Point q = ray[i - 1];
    if (p.x != q.x && p.y != q.y) {
      const cv::Point c1(q.x, p.y), c2(p.x, q.y);
      if (IsSetPixel(sk, c1) && IsSetPixel(sk, c2) && !own(c1) && !own(c2)) {
        *hit = c1;
        return true;
      }
    }
  }
  return false;
}

bool IsLineEnd(EndDirection d) { return d == EndDirection::kTop || d == EndDirection::kBottom; }

}  // namespace

bool RepairParams::IsValid(std::string* error) const {
  auto fail = [error](const char* why) {
    if (error) *error = why;
    return false;
  };
  if (max_line_gap <= 0 || max_segment_gap <= 0 || max_segment_reach < 0 || max_line_reach < 0)
    return fail("repair distances must be positive");
  if (miss_fraction < 0 || miss_constant < 0) return fail("miss tolerances must not be negative");
  if (direction_probe < 1) return fail("direction_probe must be at least 1 pixel");
  if (min_junction_distance < 0) return fail("min_junction_distance must not be negative");
  return true;
}

std::string_view ToString(RepairKind kind) {
  switch (kind) {
    case RepairKind::kLineGap:
      return "line_gap";
    case RepairKind::kSegmentGap:
      return "segment_gap";
    case RepairKind::kSegmentReach:
      return "segment_reach";
    case RepairKind::kLineReach:
      return "line_reach";
  }
  return "?";
}

std::vector<Repair> RepairRound(const JunctionNetwork& network,
                                const std::vector<LoopRecord>& loops, const RepairParams& params,
                                cv::Mat& skeleton) {
  const SkeletonGraph& g = network.graph();
  std::vector<EndInfo> ends;
  std::vector<std::vector<int>> ends_of_loop;
  for (const LoopRecord& loop : loops) {
    std::vector<int> mine;
    for (const LoopEvent& ev : loop.events) {
      if (!ev.is_end) continue;
      const SkeletonNode& n = g.nodes()[ev.node];
      if (n.rotation.size() != 1) continue;
      EndInfo e;
      e.node = ev.node;
      e.pixel = n.pixels.front();
      e.onward = -g.Departure(n.rotation.front());
      e.end = ev.end;
      e.loop_class = loop.cls;
      mine.push_back(static_cast<int>(ends.size()));
      ends.push_back(e);
    }
    ends_of_loop.push_back(std::move(mine));
  }

  // Thesis Tables 5.1-5.4: facing end points of one loop belong to one line
  // (TEP-BEP) or one segment (LEP-REP).
  std::vector<Candidate> candidates;
  for (const std::vector<int>& mine : ends_of_loop) {
    for (int i : mine) {
      for (int j : mine) {
        if (i == j) continue;
        const EndInfo& a = ends[i];
        const EndInfo& b = ends[j];
        RepairKind kind;
        double max_gap;
        if (a.end == EndDirection::kBottom && b.end == EndDirection::kTop &&
            b.pixel.y > a.pixel.y) {
          kind = RepairKind::kLineGap;
          max_gap = params.max_line_gap;
        } else if (a.end == EndDirection::kRight && b.end == EndDirection::kLeft &&
                   b.pixel.x > a.pixel.x) {
          kind = RepairKind::kSegmentGap;
          max_gap = params.max_segment_gap;
        } else {
          continue;
        }
        const cv::Point2d pa(a.pixel.x, a.pixel.y), pb(b.pixel.x, b.pixel.y);
        const double gap = std::hypot(pb.x - pa.x, pb.y - pa.y);
        if (gap > max_gap) continue;
        double along_a, miss_a, along_b, miss_b;
        RayMiss(pa, a.onward, pb, &along_a, &miss_a);
        RayMiss(pb, b.onward, pa, &along_b, &miss_b);
        const double tolerance = params.miss_fraction * gap + params.miss_constant;
        if (along_a <= 0 || along_b <= 0 || miss_a > tolerance || miss_b > tolerance) continue;
        candidates.push_back({gap + 2.0 * (miss_a + miss_b), i, j, kind});
      }
    }
  }
  std::sort(candidates.begin(), candidates.end(),
            [](const Candidate& x, const Candidate& y) { return x.cost < y.cost; });

  std::vector<Repair> done;
  std::vector<char> used(ends.size(), 0);
  // Line gaps first, then segment gaps (thesis 5.1.4.7: lines before junctions).
  for (RepairKind pass : {RepairKind::kLineGap, RepairKind::kSegmentGap}) {
    for (const Candidate& c : candidates) {
      if (c.kind != pass || used[c.a] || used[c.b]) continue;
      const EndInfo& a = ends[c.a];
      const EndInfo& b = ends[c.b];
      if (!ChordIsClear(skeleton, a.pixel, b.pixel)) continue;
      FillGap(skeleton, a.pixel, b.pixel);
      used[c.a] = used[c.b] = 1;
      done.push_back({c.kind, a.pixel, b.pixel, a.loop_class});
    }
  }
  // Thesis 5.1.4.5: a segment end left over is extended until it meets a line
  // (sealed above or already there); the meeting point is the missing junction.
  for (int pass = 0; pass < 2; ++pass) {
    const bool segments = pass == 0;
    for (size_t i = 0; i < ends.size(); ++i) {
      const EndInfo& e = ends[i];
      if (used[i] || IsLineEnd(e.end) == segments) continue;
      cv::Point hit;
      const double reach = segments ? params.max_segment_reach : params.max_line_reach;
      if (!Reach(skeleton, g, e, reach, &hit)) continue;
      bool crowded = false;
      for (const SkeletonNode& n : g.nodes())
        crowded |=
            n.kind == NodeKind::kJunction &&
            std::hypot(n.centre.x - hit.x, n.centre.y - hit.y) < params.min_junction_distance;
      if (crowded) continue;
      FillGap(skeleton, e.pixel, hit);
      used[i] = 1;
      done.push_back({segments ? RepairKind::kSegmentReach : RepairKind::kLineReach, e.pixel, hit,
                      e.loop_class});
    }
  }
  return done;
}

}  // namespace bsls::interpretation
