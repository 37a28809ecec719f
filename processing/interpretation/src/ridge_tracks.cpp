#include "bsls/interpretation/ridge_tracks.h"

#include <algorithm>
#include <cmath>
#include <optional>
#include <stdexcept>

#include "bsls/geometry/curve_fit.h"

namespace bsls::interpretation {
namespace {

// The first ridge point of line track t.
extraction::RidgePoint FirstOf(const TrackNetwork& net, int t) {
  return net.rows.points[net.lines[t].points.front()];
}
// The last ridge point of line track t.
extraction::RidgePoint LastOf(const TrackNetwork& net, int t) {
  return net.rows.points[net.lines[t].points.back()];
}

// Gaps in lines: each track's end and the start of the nearest track
// beginning within bridge_rows below it, when each is the other's nearest,
// as net->line_below and net->line_above.
void BridgeLineGaps(const TrackParams& params, TrackNetwork* net) {
  const int n_lines = static_cast<int>(net->lines.size());
  auto first = [net](int t) { return FirstOf(*net, t); };
  auto last = [net](int t) { return LastOf(*net, t); };
  auto gap = [&](int above, int below) {
    const extraction::RidgePoint a = last(above), b = first(below);
    const int rows_between = b.y - a.y;
    if (rows_between < 1 || rows_between > params.bridge_rows) return -1.0;
    const double d = std::hypot(b.x - a.x, static_cast<double>(rows_between));
    return d <= params.bridge_distance ? d : -1.0;
  };
  // Tracks by the row of their first point, each row's by its x, so that a
  // track's end looks only at the starts it can reach (linear in tracks).
  std::vector<std::vector<int>> starting(
      net->rows.row_start.empty() ? 0 : net->rows.row_start.size() - 1);
  for (int b = 0; b < n_lines; ++b) starting[first(b).y].push_back(b);
  for (std::vector<int>& row : starting)
    std::sort(row.begin(), row.end(), [&](int u, int v) { return first(u).x < first(v).x; });
  std::vector<int> nearest_below(n_lines, -1), nearest_above(n_lines, -1);
  std::vector<double> below_d(n_lines, 0), above_d(n_lines, 0);
  for (int a = 0; a < n_lines; ++a) {
    const extraction::RidgePoint end = last(a);
    const int y_end =
        std::min<int>(end.y + params.bridge_rows, static_cast<int>(starting.size()) - 1);
    for (int y = end.y + 1; y <= y_end; ++y) {
      const std::vector<int>& row = starting[y];
      auto k = std::lower_bound(row.begin(), row.end(), end.x - params.bridge_distance,
                                [&](int b, double x) { return first(b).x < x; });
      for (; k != row.end() && first(*k).x <= end.x + params.bridge_distance; ++k) {
        const int b = *k;
        if (a == b) continue;
        const double d = gap(a, b);
        if (d < 0) continue;
        // Ties go to the lower index, as a scan of every pair in order gives.
        if (nearest_below[a] < 0 || d < below_d[a] || (d == below_d[a] && b < nearest_below[a])) {
          nearest_below[a] = b;
          below_d[a] = d;
        }
        if (nearest_above[b] < 0 || d < above_d[b]) {
          nearest_above[b] = a;
          above_d[b] = d;
        }
      }
    }
  }
  net->line_below.assign(n_lines, -1);
  net->line_above.assign(n_lines, -1);
  for (int a = 0; a < n_lines; ++a) {
    const int b = nearest_below[a];
    if (b >= 0 && nearest_above[b] == a) {
      net->line_below[a] = b;
      net->line_above[b] = a;
    }
  }
}

// A bridged gap crossing a row: its chord's x half a row down, and the line
// track above the gap.
struct GapAtRow {
  double x;
  int a;
};

// The bridged gaps by row: gap a (the chord from line a's last point to
// the first of line_below[a]) is listed at every row from its upper end to
// the row before its lower end, with its x half a row down; each row's by
// that x. A chord moves at most bridge_distance in x over a row.
std::vector<std::vector<GapAtRow>> GapsByRow(const TrackNetwork& net) {
  std::vector<std::vector<GapAtRow>> gaps_at(
      net.rows.row_start.empty() ? 0 : net.rows.row_start.size() - 1);
  for (int a = 0; a < static_cast<int>(net.lines.size()); ++a) {
    if (net.line_below[a] < 0) continue;
    const extraction::RidgePoint p0 = LastOf(net, a), p1 = FirstOf(net, net.line_below[a]);
    for (int y = p0.y; y < p1.y; ++y)
      gaps_at[y].push_back({p0.x + (p1.x - p0.x) * (y + 0.5 - p0.y) / (p1.y - p0.y), a});
  }
  for (std::vector<GapAtRow>& row : gaps_at)
    std::sort(row.begin(), row.end(),
              [](const GapAtRow& u, const GapAtRow& v) { return u.x < v.x; });
  return gaps_at;
}

// The line point of row y within [lo, hi] nearest to `at`, or -1. A row's
// points run left to right: only those within [lo, hi] are looked at.
int NearestLinePoint(const TrackNetwork& net, int y, double lo, double hi, double at) {
  int best = -1;
  const auto row = net.rows.Row(y);
  const auto from = std::partition_point(
      row.begin(), row.end(), [lo](const extraction::RidgePoint& r) { return r.x < lo; });
  for (size_t k = static_cast<size_t>(from - row.begin()); k < row.size() && row[k].x <= hi; ++k) {
    const int i = net.rows.row_start[y] + static_cast<int>(k);
    if (net.line_of_point[i] < 0) continue;
    if (best < 0 || std::abs(row[k].x - at) < std::abs(net.rows.points[best].x - at)) best = i;
  }
  return best;
}

// The row of segment t's end (its left or right end, in column points):
// its end point's; where its last points bend away from a straight line
// through the points a few columns in (next to the line the light of both
// strokes can pull them, at a line's end most), that line's. `in` is
// scratch space.
double EndRow(const extraction::RidgePoints& columns, const std::vector<int>& t, bool left_end,
              const TrackParams& params, geometry::Samples* in) {
  const auto& cp = columns.points;  // x: image row, y: image column
  const extraction::RidgePoint& end = cp[left_end ? t.front() : t.back()];
  const double ex = end.y;
  double ey = end.x;
  const int n_points = static_cast<int>(t.size());
  if (n_points >= params.end_skip + 2) {
    in->clear();
    for (int k = params.end_skip; k < std::min(n_points, params.end_skip + params.end_fit); ++k) {
      const extraction::RidgePoint& q = cp[left_end ? t[k] : t[n_points - 1 - k]];
      in->emplace_back(q.y - ex, q.x);
    }
    double at_end, slope;  // the fit's row at the end's column
    if (geometry::FitLine(*in, &at_end, &slope) && std::abs(at_end - ey) > params.end_bend)
      ey = at_end;
  }
  return ey;
}

// No ridge point where a segment's end (row ey, columns lo..hi) meets a
// line: the end may meet one across a gap, on the chord joining its two
// tracks (a break next to the junction); of several, the first line's.
// Sets j's line and position there, or leaves its line -1.
void MeetAcrossGap(const TrackNetwork& net, double ey, double lo, double hi,
                   const TrackParams& params, const std::vector<std::vector<GapAtRow>>& gaps_at,
                   TrackJunction* j) {
  const int gap_row = std::isfinite(ey) ? static_cast<int>(std::floor(ey)) : -1;
  if (gap_row < 0 || gap_row >= static_cast<int>(gaps_at.size())) return;
  const std::vector<GapAtRow>& crossing = gaps_at[gap_row];
  auto g = std::partition_point(crossing.begin(), crossing.end(), [&](const GapAtRow& c) {
    return c.x < lo - params.bridge_distance;
  });
  for (; g != crossing.end() && g->x <= hi + params.bridge_distance; ++g) {
    const int a = g->a;
    if (j->line >= 0 && a > j->line) continue;
    const extraction::RidgePoint p0 = LastOf(net, a), p1 = FirstOf(net, net.line_below[a]);
    if (ey <= p0.y || ey >= p1.y) continue;
    const double x = p0.x + (p1.x - p0.x) * (ey - p0.y) / (p1.y - p0.y);
    if (x < lo || x > hi) continue;
    j->line = a;
    j->position = {x, ey};
  }
}

// The junction where one end of segment s meets a line within end_reach
// (on the end's own half of the segment, split at column `middle`), or
// nullopt where it meets none. `in` is scratch space.
std::optional<TrackJunction> JunctionAtEnd(const TrackNetwork& net, int s, bool left_end,
                                           double middle, int towards_p, const TrackParams& params,
                                           const std::vector<std::vector<GapAtRow>>& gaps_at,
                                           geometry::Samples* in) {
  const std::vector<int>& t = net.segments[s].points;
  const extraction::RidgePoint& end = net.columns.points[left_end ? t.front() : t.back()];
  const double ex = end.y;
  const double ey = EndRow(net.columns, t, left_end, params, in);
  const double lo = left_end ? ex - params.end_reach : std::max(ex - params.end_reach, middle);
  const double hi = left_end ? std::min(ex + params.end_reach, middle) : ex + params.end_reach;
  int hit = -1;
  for (const int dy : {0, -1, 1}) {
    hit = NearestLinePoint(net, static_cast<int>(std::lround(ey)) + dy, lo, hi, ex);
    if (hit >= 0) break;
  }
  TrackJunction j;
  if (hit >= 0) {
    j.line = net.line_of_point[hit];
    j.position = {net.rows.points[hit].x, static_cast<double>(net.rows.points[hit].y)};
  } else {
    MeetAcrossGap(net, ey, lo, hi, params, gaps_at, &j);
    if (j.line < 0) return std::nullopt;
  }
  j.segment = s;
  // The left end meets the line on its left: the segment lies to its right.
  j.segment_left = !left_end;
  const int segment_direction = j.segment_left ? -1 : +1;
  j.kind = segment_direction == towards_p ? pattern::JunctionKind::kDirect
                                          : pattern::JunctionKind::kCorresponding;
  return j;
}

// The junctions where the segments' ends meet lines, into net->junctions.
void FindJunctions(pattern::Side side, const TrackParams& params,
                   const std::vector<std::vector<GapAtRow>>& gaps_at, const Cancellation& cancel,
                   TrackNetwork* net) {
  const int towards_p = pattern::ImageDirectionOfIncreasingP(side);
  const auto& cp = net->columns.points;  // x: image row, y: image column
  geometry::Samples in;                  // a segment's end: (column - the end's column, row)
  for (int s = 0; s < static_cast<int>(net->segments.size()); ++s) {
    if (s % 4096 == 0) cancel.ThrowIfRequested("the junctions");
    const std::vector<int>& t = net->segments[s].points;
    if (static_cast<int>(t.size()) < params.min_segment) continue;
    // The segment's middle column: each end looks for its line on its own
    // half, so that a short segment's two ends find their two lines.
    const double middle = 0.5 * (cp[t.front()].y + cp[t.back()].y);
    const size_t first_junction = net->junctions.size();
    for (const bool left_end : {true, false})
      if (auto j = JunctionAtEnd(*net, s, left_end, middle, towards_p, params, gaps_at, &in))
        net->junctions.push_back(*j);
    // A segment joins two lines; one whose ends both meet the same line
    // (a speck of light beside it) makes no junction.
    if (net->junctions.size() == first_junction + 2 &&
        net->junctions[first_junction].line == net->junctions[first_junction + 1].line)
      net->junctions.resize(first_junction);
  }
}

}  // namespace

bool TrackParams::IsValid(std::string* error) const {
  auto fail = [error](const char* why) {
    if (error) *error = why;
    return false;
  };
  if (!(max_step > 0)) return fail("max_step must be positive");
  if (min_track < 1) return fail("min_track must be at least 1");
  if (min_segment < 1) return fail("min_segment must be at least 1");
  if (!(end_reach > 0)) return fail("end_reach must be positive");
  if (end_skip < 0 || end_fit < 2) return fail("end_skip must be >= 0 and end_fit >= 2");
  if (!(end_bend >= 0)) return fail("end_bend must not be negative");
  if (bridge_rows < 1) return fail("bridge_rows must be at least 1");
  if (!(bridge_distance > 0)) return fail("bridge_distance must be positive");
  if (!(max_segment_slope > 0)) return fail("max_segment_slope must be positive");
  if (steep_columns < 2) return fail("steep_columns must be at least 2");
  return true;
}

std::vector<Track> LinkTracks(const extraction::RidgePoints& points, const TrackParams& params,
                              std::vector<int>* track_of_point, const Cancellation& cancel,
                              std::string_view stage) {
  const auto& pts = points.points;
  const int n = static_cast<int>(pts.size());
  std::vector<int> next(n, -1), prev(n, -1);
  const int rows = static_cast<int>(points.row_start.size()) - 1;
  const float reach = static_cast<float>(params.max_step);
  for (int y = 0; y + 1 < rows; ++y) {
    if (y % 32 == 0) cancel.ThrowIfRequested(stage);
    const int below_end = points.row_start[y + 2];
    int j = points.row_start[y + 1];  // both rows run left to right
    for (int i = points.row_start[y]; i < points.row_start[y + 1]; ++i) {
      const float x = pts[i].x;
      while (j < below_end && pts[j].x < x - reach) ++j;
      int best = -1;
      float best_d = reach;
      for (int k = j; k < below_end && pts[k].x <= x + reach; ++k) {
        const float d = std::abs(pts[k].x - x);
        if (best < 0 || d < best_d) {
          best = k;
          best_d = d;
        }
      }
      if (best < 0) continue;
      if (prev[best] >= 0) {
        // Claimed already: the nearer claimant keeps it.
        if (std::abs(pts[prev[best]].x - pts[best].x) <= best_d) continue;
        next[prev[best]] = -1;
      }
      prev[best] = i;
      next[i] = best;
    }
  }
  std::vector<Track> tracks;
  if (track_of_point) track_of_point->assign(n, -1);
  for (int i = 0; i < n; ++i) {
    if (i % 8192 == 0) cancel.ThrowIfRequested(stage);
    if (prev[i] >= 0) continue;
    Track t;
    for (int k = i; k >= 0; k = next[k]) t.points.push_back(k);
    if (static_cast<int>(t.points.size()) < params.min_track) continue;
    if (track_of_point)
      for (int k : t.points) (*track_of_point)[k] = static_cast<int>(tracks.size());
    tracks.push_back(std::move(t));
  }
  return tracks;
}

std::vector<Track> CutSteepStretches(const extraction::RidgePoints& columns,
                                     std::vector<Track> segments, const TrackParams& params,
                                     const Cancellation& cancel) {
  const auto& cp = columns.points;  // x: image row, y: image column
  const int w = params.steep_columns;
  std::vector<Track> out;
  std::vector<char> steep;
  int cut = 0;
  for (Track& t : segments) {
    if (++cut % 1024 == 0) cancel.ThrowIfRequested("the segment tracks");
    const int n = static_cast<int>(t.points.size());
    // Every point of a window of w + 1 points (w columns) that climbs too
    // steeply belongs to a steep stretch.
    steep.assign(n, 0);
    bool any = false;
    for (int i = 0; i + w < n; ++i)
      if (std::abs(cp[t.points[i + w]].x - cp[t.points[i]].x) > params.max_segment_slope * w) {
        std::fill(steep.begin() + i, steep.begin() + i + w + 1, 1);
        any = true;
      }
    if (!any) {
      out.push_back(std::move(t));
      continue;
    }
    for (int i = 0; i < n;) {
      if (steep[i]) {
        ++i;
        continue;
      }
      Track piece;
      for (; i < n && !steep[i]; ++i) piece.points.push_back(t.points[i]);
      if (static_cast<int>(piece.points.size()) >= params.min_track)
        out.push_back(std::move(piece));
    }
  }
  return out;
}

TrackNetwork BuildTrackNetwork(extraction::RidgePoints rows, extraction::RidgePoints columns,
                               pattern::Side side, const TrackParams& params,
                               const Cancellation& cancel) {
  std::string why;
  if (!params.IsValid(&why)) throw std::invalid_argument("BuildTrackNetwork: " + why);
  TrackNetwork net;
  net.rows = std::move(rows);
  net.columns = std::move(columns);
  net.lines = LinkTracks(net.rows, params, &net.line_of_point, cancel, "the line tracks");
  cancel.ThrowIfRequested("the line tracks");
  net.segments = CutSteepStretches(
      net.columns, LinkTracks(net.columns, params, nullptr, cancel, "the segment tracks"), params,
      cancel);
  cancel.ThrowIfRequested("the segment tracks");

  BridgeLineGaps(params, &net);
  cancel.ThrowIfRequested("the bridges across line gaps");
  FindJunctions(side, params, GapsByRow(net), cancel, &net);
  net.junctions_on_line.assign(net.lines.size(), {});
  for (int i = 0; i < static_cast<int>(net.junctions.size()); ++i)
    net.junctions_on_line[net.junctions[i].line].push_back(i);
  for (auto& on_line : net.junctions_on_line)
    std::sort(on_line.begin(), on_line.end(), [&](int a, int b) {
      return net.junctions[a].position.y < net.junctions[b].position.y;
    });
  return net;
}

}  // namespace bsls::interpretation
