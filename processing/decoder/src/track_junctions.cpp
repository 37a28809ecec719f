#include "track_junctions.h"

#include <algorithm>
#include <cmath>
#include <optional>

#include "bsls/extraction/stripe_centre.h"
#include "junction_placement.h"

namespace bsls::decoder::internal {

using geometry::FitAtZero;
using geometry::FitLine;
using geometry::Sample;
using geometry::Samples;

namespace {

// Thesis 5.2, as the skeleton chain plans it: what placing track junction
// j fits (junction_placement.h). The line: its measured centres within
// junction_fit_rows of the junction (the rows beside its junctions were
// never measured), or where too few, its ridge points clear of the
// junction. The segment: its first track_chain.segment_columns column
// ridge points from the line outwards, those within junction_clearance of
// the line left out, and never its last two columns (where the far line's
// light biases them); they end where the track turns steeper than 45
// degrees over three columns (it runs on into a line there). The columns
// are measured by RidgeCentreInColumn: StripeCentreInColumn, or more
// columns, moved junctions beside the outside corpus's noses 2.5-3.7 px
// (docs/decoding.md, "Which chain").
JunctionPlan PlanTrackJunction(const interpretation::TrackNetwork& net, int j,
                               const TrackCentres& line, const DecodeParams& params) {
  const interpretation::TrackJunction& junction = net.junctions[j];
  const double y0 = junction.position.y;
  const int fit = params.junction_fit_rows;
  JunctionPlan plan;
  plan.vertical = CentresNear(line, y0, fit);
  if (plan.vertical.size() >= 3 && FitLine(plan.vertical, &plan.a, &plan.b)) {
    plan.wide = CentresNear(line, y0, 2 * fit);
  } else {
    plan.vertical.clear();
    for (int k : net.lines[junction.line].points) {
      const extraction::RidgePoint& q = net.rows.points[k];
      const double t = q.y - y0;
      if (std::abs(t) <= fit && std::abs(t) > params.junction_clearance)
        plan.vertical.emplace_back(t, q.x);
    }
    if (plan.vertical.size() < 3 || !FitLine(plan.vertical, &plan.a, &plan.b)) return plan;
  }
  plan.ok = true;
  plan.columns.reserve(static_cast<size_t>(params.track_chain.segment_columns));
  const auto& seg = net.segments[junction.segment].points;
  const auto& cp = net.columns.points;  // x: image row, y: image column
  const int n = static_cast<int>(seg.size());
  // The segment's k-th column ridge point counted from the line.
  auto outward = [&](int k) -> const extraction::RidgePoint& {
    return cp[seg[junction.segment_left ? n - 1 - k : k]];
  };
  for (int k = 0;
       k < n - 2 && static_cast<int>(plan.columns.size()) < params.track_chain.segment_columns;
       ++k) {
    const extraction::RidgePoint& q = outward(k);
    if (!plan.columns.empty() && k >= 3) {
      const extraction::RidgePoint& back = outward(k - 3);
      if (std::abs(q.x - back.x) > std::abs(q.y - back.y)) break;
    }
    if (std::abs(q.y - plan.a) <= params.junction_clearance) continue;
    plan.columns.emplace_back(q.y, static_cast<int>(std::lround(q.x)));
  }
  return plan;
}

// Whether the plan's line runs straight on through its junction: measured
// on both sides, with slopes that differ by at most fold_slope_change
// (else it folds there, or turns too steep for its track beyond, and
// PlaceJunction meets the segment with the track itself).
bool StraightThrough(const JunctionPlan& plan, const DecodeParams& params) {
  if (!plan.ok) return false;
  std::vector<std::pair<double, double>> above, below;
  for (const auto& v : plan.vertical) (v.first < 0 ? above : below).push_back(v);
  double a0, b0, a1, b1;
  return FitLine(above, &a0, &b0) && FitLine(below, &a1, &b1) &&
         std::abs(b0 - b1) <= params.fold_slope_change;
}

// Where junction j lies: the segment's centres near the line fitted as a
// straight line y(x) and met with the line's centres fitted as x(y).
cv::Point2d PlaceJunction(const cv::Mat& grey, const interpretation::TrackNetwork& net, int j,
                          const TrackCentres& line, const JunctionPlan& plan,
                          const DecodeParams& params) {
  const interpretation::TrackJunction& junction = net.junctions[j];
  cv::Point2d at = junction.position;
  const int fit_rows = params.junction_fit_rows;
  Samples near;
  auto line_x = [&](double y) -> std::optional<double> {
    const int row = static_cast<int>(std::lround(y));
    MeasuredNear(line, row, fit_rows, false, &near);
    for (auto& s : near) s.first -= y - row;  // t relative to y itself
    if (near.size() < 2) return std::nullopt;
    return FitAtZero(near);
  };
  if (auto x = line_x(at.y)) at.x = *x;
  // The segment: the plan's measured columns, or where they give no fit,
  // its columns nearest the line, clear of its light.
  auto fit_nearest_columns = [&](double* a, double* b) {
    const auto& seg = net.segments[junction.segment].points;
    const auto& cp = net.columns.points;  // x: image row, y: image column
    Samples columns;
    auto take = [&](int k) {
      const extraction::RidgePoint& p = cp[k];
      if (std::abs(p.y - at.x) <= params.junction_clearance) return;
      if (auto y = extraction::RidgeCentreInColumn(grey, p.y, p.x))
        columns.emplace_back(p.y - at.x, *y);
    };
    const int want = params.track_chain.segment_columns;
    if (junction.segment_left) {
      for (int i = static_cast<int>(seg.size()) - 1;
           i >= 0 && static_cast<int>(columns.size()) < want; --i)
        take(seg[i]);
    } else {
      for (size_t i = 0; i < seg.size() && static_cast<int>(columns.size()) < want; ++i)
        take(seg[i]);
    }
    return FitLine(columns, a, b);
  };
  double a, b;  // the segment: y = a + b (x - x_ref)
  const double x_ref = at.x;
  if (double c, e; plan.ok && FitMeasuredSegment(plan, params, &c, &e)) {
    a = c + e * (x_ref - plan.a);
    b = e;
  } else if (!fit_nearest_columns(&a, &b)) {
    return at;
  }
  // Where the line folds at the junction (its slope above and below differs
  // by more than fold_slope_change: the side of the nose, the lips) no one
  // curve fits both branches, and where it has centres on one side only (it
  // turns too steep for the track beyond) none reaches the junction: there
  // the junction is where the segment's line crosses the track itself.
  MeasuredNear(line, static_cast<int>(std::lround(at.y)), fit_rows, false, &near);
  Samples above, below;
  for (const Sample& s : near) (s.first < 0 ? above : below).push_back(s);
  double a_above, b_above, a_below, b_below;
  const bool both_sides = FitLine(above, &a_above, &b_above) && FitLine(below, &a_below, &b_below);
  if (!both_sides || std::abs(b_above - b_below) > params.fold_slope_change) {
    // The track's ridge points, with those of the tracks continuing it
    // across a gap above and below (joined by a chord, or by the steep
    // stretch that carries it on), or of its steep tail.
    std::vector<cv::Point2d> path;
    auto add = [&](int track, bool tail) {
      const auto& pts = net.lines[track].points;
      const size_t count = std::min(pts.size(), static_cast<size_t>(fit_rows + 1));
      const size_t from = tail ? pts.size() - count : 0, to = tail ? pts.size() : count;
      for (size_t k = from; k < to; ++k)
        path.emplace_back(net.rows.points[pts[k]].x, net.rows.points[pts[k]].y);
    };
    if (net.line_above[junction.line] >= 0) add(net.line_above[junction.line], true);
    for (int k : net.lines[junction.line].points)
      path.emplace_back(net.rows.points[k].x, net.rows.points[k].y);
    const std::vector<cv::Point2d>& on = net.path_below[junction.line];
    if (on.size() > 2) path.insert(path.end(), on.begin() + 1, on.end() - 1);
    if (net.line_below[junction.line] >= 0) add(net.line_below[junction.line], false);
    if (net.line_below[junction.line] < 0 && on.size() > 2) path.push_back(on.back());
    auto off = [&](const cv::Point2d& q) { return q.y - (a + b * (q.x - x_ref)); };
    std::optional<cv::Point2d> crossing;
    double nearest = fit_rows + 1.0;
    for (size_t k = 0; k + 1 < path.size(); ++k) {
      const double d0 = off(path[k]), d1 = off(path[k + 1]);
      if ((d0 > 0) == (d1 > 0) && d0 != 0) continue;
      const double f = d0 == d1 ? 0.0 : d0 / (d0 - d1);  // both on the line: the first
      const double x = path[k].x + f * (path[k + 1].x - path[k].x);
      const cv::Point2d c(x, a + b * (x - x_ref));
      if (std::abs(c.y - a) < nearest) {
        nearest = std::abs(c.y - a);
        crossing = c;
      }
    }
    if (crossing) return *crossing;
  }
  at.y = a;
  if (auto x = line_x(at.y)) {
    // Once more at the line's x there.
    at.y = a + b * (*x - x_ref);
    at.x = *x;
  }
  return at;
}

// Junctions: one per label; where two claim one, the one on a track of
// its own p (then the first) keeps it. Returns the keepers by label, and
// adds the others to *conflicts.
std::vector<int> JunctionPerLabel(const interpretation::TrackNetwork& net,
                                  const interpretation::TrackLabels& labels, int* conflicts) {
  std::vector<std::tuple<int, int, int>> claims;  // (p, v, junction), in junction order
  for (int j = 0; j < static_cast<int>(net.junctions.size()); ++j)
    if (labels.p[j] != interpretation::kUnlabelled)
      claims.emplace_back(labels.p[j], labels.v[j], j);
  std::sort(claims.begin(), claims.end());
  auto on_own_line = [&](int j) { return labels.line_p[net.junctions[j].line] == labels.p[j]; };
  std::vector<int> placed;
  for (size_t i = 0; i < claims.size();) {
    size_t k = i;
    int keeper = std::get<2>(claims[i]);
    for (; k < claims.size() && std::get<0>(claims[k]) == std::get<0>(claims[i]) &&
           std::get<1>(claims[k]) == std::get<1>(claims[i]);
         ++k)
      if (!on_own_line(keeper) && on_own_line(std::get<2>(claims[k])))
        keeper = std::get<2>(claims[k]);
    *conflicts += static_cast<int>(k - i) - 1;
    placed.push_back(keeper);
    i = k;
  }
  return placed;
}

}  // namespace

// Orders unlabelled junctions by y, as DecodeResult::unlabelled is.
void SortByRow(std::vector<UnlabelledJunction>* junctions) {
  std::sort(junctions->begin(), junctions->end(),
            [](const UnlabelledJunction& a, const UnlabelledJunction& b) {
              return a.position.y < b.position.y;
            });
}

// Junctions seen whose label could not be proven: reported at their ridge
// points (full frame), not placed, ordered by y.
std::vector<UnlabelledJunction> UnlabelledJunctions(const interpretation::TrackNetwork& net,
                                                    const interpretation::TrackLabels& labels,
                                                    const WorkingScale& scale) {
  std::vector<UnlabelledJunction> out;
  for (int j = 0; j < static_cast<int>(net.junctions.size()); ++j)
    if (labels.p[j] == interpretation::kUnlabelled)
      out.push_back({scale.ToFull(net.junctions[j].position), net.junctions[j].kind});
  SortByRow(&out);
  return out;
}

// The labelled junctions of the network, one per label (JunctionPerLabel),
// placed (thesis 5.2) in the full frame: planned with their segments'
// columns measured, then placed, each step in parallel.
std::vector<DecodedJunction> PlaceTrackJunctions(const cv::Mat& working,
                                                 const interpretation::TrackNetwork& net,
                                                 const interpretation::TrackLabels& labels,
                                                 const std::vector<TrackCentres>& centres,
                                                 const DecodeParams& params,
                                                 const WorkingScale& scale, int* conflicts) {
  const std::vector<int> placed = JunctionPerLabel(net, labels, conflicts);
  const cv::Range all(0, static_cast<int>(placed.size()));
  std::vector<JunctionPlan> plans(placed.size());
  // Each plan measures its own columns: a segment's two junctions share
  // few of them here, and gathering them once costs more than it saves.
  cv::parallel_for_(all, [&](const cv::Range& r) {
    for (int i = r.start; i < r.end; ++i) {
      JunctionPlan& plan = plans[i];
      plan = PlanTrackJunction(net, placed[i], centres[net.junctions[placed[i]].line], params);
      plan.centres.reserve(plan.columns.size());
      for (const cv::Point& c : plan.columns)
        plan.centres.push_back(extraction::RidgeCentreInColumn(working, c.x, c.y));
    }
  });
  const int q_offset = params.q_offset.value_or(0);
  std::vector<DecodedJunction> junctions(placed.size());
  cv::parallel_for_(all, [&](const cv::Range& r) {
    for (int i = r.start; i < r.end; ++i) {
      const int j = placed[i];
      DecodedJunction& d = junctions[i];
      d.p = labels.p[j];
      d.q = labels.v[j] + q_offset;
      d.kind = net.junctions[j].kind;
      std::optional<cv::Point2d> at;
      if (StraightThrough(plans[i], params))
        at = RefineJunction(plans[i], net.junctions[j].position.y, params, 1);
      if (!at)
        at = PlaceJunction(working, net, j, centres[net.junctions[j].line], plans[i], params);
      d.position = scale.ToFull(*at);
      plans[i] = {};  // freed here, in parallel, not one by one at the end
    }
  });
  return junctions;
}

}  // namespace bsls::decoder::internal
