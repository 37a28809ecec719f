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
  net->path_below.assign(n_lines, {});
  for (int a = 0; a < n_lines; ++a) {
    const int b = nearest_below[a];
    if (b >= 0 && nearest_above[b] == a) {
      net->line_below[a] = b;
      net->line_above[b] = a;
      const extraction::RidgePoint p0 = last(a), p1 = first(b);
      net->path_below[a] = {{p0.x, static_cast<double>(p0.y)}, {p1.x, static_cast<double>(p1.y)}};
    }
  }
}

int NearestLinePoint(const TrackNetwork& net, int y, double lo, double hi, double at);

// Following a line on where it leans past max_step, through the column
// ridge points (docs/decoding.md, "Lines that lean past the row tracks").
constexpr int kLeanRows = 5;          // rows over which a line track's lean is measured
constexpr double kMinLean = 0.3;      // px per row: a track leaning less ended for another reason
constexpr int kSlopeColumns = 3;      // columns over which a column track's slope is measured
constexpr double kMaxTurnDeg = 40.0;  // the column track goes on within this of the line's lean
constexpr double kMinDescent = 0.15;  // rows per column: flatter, the column track is a segment
constexpr double kSegmentLike = 0.2;  // rows per column of the frame's typical segment slope
constexpr double kOtherLine = 1.5;    // px: a row ridge point this close is another line's
constexpr int kMaxPieces = 8;         // column tracks followed one after another

// A column ridge point in image (x, y).
cv::Point2d ColumnPoint(const TrackNetwork& net, int k) {
  const extraction::RidgePoint& c = net.columns.points[k];  // x: image row, y: image column
  return {static_cast<double>(c.y), c.x};
}

// The median slope (rows per column) of the segment tracks of 8 points or
// more: how the frame's segments run. Near 0 where the projector sits
// beside the camera (the thesis's rig, 2.2), which is taken where fewer
// than kSlopeSample segments tell.
double TypicalSegmentSlope(const TrackNetwork& net) {
  constexpr size_t kSlopeSample = 16;
  std::vector<double> slopes;
  for (const Track& t : net.segments) {
    if (t.points.size() < 8) continue;
    const cv::Point2d a = ColumnPoint(net, t.points.front()), b = ColumnPoint(net, t.points.back());
    slopes.push_back((b.y - a.y) / (b.x - a.x));
  }
  if (slopes.size() < kSlopeSample) return 0.0;
  std::nth_element(slopes.begin(), slopes.begin() + slopes.size() / 2, slopes.end());
  return slopes[slopes.size() / 2];
}

// Lines leaning past max_step where a surface turns away (the base of the
// nose, a lump's skirt): the row tracks stop near 50 degrees from the
// vertical, and the line goes on in the column ridge points, as a steep
// stretch or a piece of a segment track. A line track leaning at least
// kMinLean px per row at its end goes on along the column track that starts
// within steep_reach of its end in the direction it leans (within
// kMaxTurnDeg, and unlike the frame's segments), for as long as that keeps
// descending and meets no other line, and on along the next such column
// track: into the line track that starts on it (a gap bridged), or to its
// end (a tail). The pieces of column tracks followed are taken out of the
// steep stretches and segments, so that they make no junctions.
class LeaningLines {
 public:
  LeaningLines(const TrackParams& params, TrackNetwork* net)
      : params_(params), net_(*net), typical_(TypicalSegmentSlope(*net)) {
    const int rows = Rows();
    // The column points by row, counted first and then placed, each row's
    // in the order of pool, track and point.
    row_start_.assign(static_cast<size_t>(rows) + 1, 0);
    auto each_place = [&](const auto& visit) {
      for (int pool = 0; pool < 2; ++pool)
        for (int t = 0; t < static_cast<int>(Pool(pool).size()); ++t) {
          const std::vector<int>& pts = Pool(pool)[t].points;
          for (int i = 0; i < static_cast<int>(pts.size()); ++i) {
            const int y = static_cast<int>(std::lround(ColumnPoint(net_, pts[i]).y));
            if (y >= 0 && y < rows) visit(y, ColumnPlace{pool, t, i});
          }
        }
    };
    each_place([&](int y, const ColumnPlace&) { ++row_start_[y + 1]; });
    for (int y = 0; y < rows; ++y) row_start_[y + 1] += row_start_[y];
    places_.resize(static_cast<size_t>(row_start_[rows]));
    std::vector<int> filled(row_start_.begin(), row_start_.end() - 1);
    each_place([&](int y, const ColumnPlace& c) { places_[filled[y]++] = c; });
    for (int pool = 0; pool < 2; ++pool) {
      used_[pool].resize(Pool(pool).size());
      for (int t = 0; t < static_cast<int>(Pool(pool).size()); ++t)
        used_[pool][t].assign(Pool(pool)[t].points.size(), 0);
    }
    starting_.resize(rows);
    for (int t = 0; t < static_cast<int>(net_.lines.size()); ++t)
      starting_[FirstOf(net_, t).y].push_back(t);
  }

  // Follows line track a on where it leans past max_step, if it does:
  // sets its path_below (and line_below where a track continues it).
  void Follow(int a) {
    const std::vector<int>& line = net_.lines[a].points;
    if (!net_.path_below[a].empty() || static_cast<int>(line.size()) <= kLeanRows) return;
    const cv::Point2d end = RowPoint(line.back());
    double lean = (end.x - RowPoint(line[line.size() - 1 - kLeanRows]).x) / kLeanRows;
    if (std::abs(lean) < kMinLean) return;
    std::vector<cv::Point2d> path{end};
    std::vector<std::pair<ColumnPlace, int>> taken;  // pieces followed: (first place, last point)
    int b = -1;
    bool stopped = false;  // at another line, or where the line turns into a segment
    for (int piece = 0; piece < kMaxPieces && b < 0 && !stopped; ++piece) {
      // A faint line breaks more often further on: twice the reach there.
      const double reach = (piece == 0 ? 1.0 : 2.0) * params_.steep_reach;
      const std::optional<ColumnPlace> from = NextPiece(path.back(), lean, reach);
      if (!from) break;
      const int last = AlongPiece(*from, a, lean > 0 ? 1 : -1, end.y, &path, &b, &stopped);
      if (last < 0) break;
      taken.push_back({*from, last});
      // The lean where this piece ends, for the next one.
      const cv::Point2d& back = path[path.size() >= 4 ? path.size() - 4 : 0];
      if (path.back().y > back.y) lean = (path.back().x - back.x) / (path.back().y - back.y);
    }
    if (b >= 0) {
      path.push_back(RowPoint(net_.lines[b].points.front()));
      net_.line_below[a] = b;
      net_.line_above[b] = a;
    } else if (path.back().y - end.y < params_.steep_columns) {
      return;  // too short a tail to follow
    }
    for (const auto& [from, last] : taken)
      for (int i = std::min(from.at, last); i <= std::max(from.at, last); ++i)
        used_[from.pool][from.track][i] = 1;
    net_.path_below[a] = std::move(path);
  }

  // Takes the pieces followed out of the steep stretches and segments.
  void RemoveFollowedPieces() {
    for (int pool = 0; pool < 2; ++pool) {
      std::vector<Track> kept;
      kept.reserve(Pool(pool).size());
      for (size_t t = 0; t < Pool(pool).size(); ++t) {
        const std::vector<char>& used = used_[pool][t];
        if (std::find(used.begin(), used.end(), 1) == used.end() &&
            static_cast<int>(used.size()) >= params_.min_track) {  // untouched: kept whole
          kept.push_back(std::move(Pool(pool)[t]));
          continue;
        }
        const std::vector<int>& pts = Pool(pool)[t].points;
        for (size_t i = 0; i < pts.size();) {
          Track piece;
          for (; i < pts.size() && !used_[pool][t][i]; ++i) piece.points.push_back(pts[i]);
          if (static_cast<int>(piece.points.size()) >= params_.min_track)
            kept.push_back(std::move(piece));
          while (i < pts.size() && used_[pool][t][i]) ++i;
        }
      }
      Pool(pool).swap(kept);
    }
  }

 private:
  // A place in a column track: which pool (0 the steep stretches, 1 the
  // segments), which track, which point.
  struct ColumnPlace {
    int pool, track, at;
  };

  int Rows() const {
    return net_.rows.row_start.empty() ? 0 : static_cast<int>(net_.rows.row_start.size()) - 1;
  }
  std::vector<Track>& Pool(int pool) { return pool == 0 ? net_.steep : net_.segments; }
  cv::Point2d RowPoint(int k) const {
    return {net_.rows.points[k].x, static_cast<double>(net_.rows.points[k].y)};
  }
  // Rows per column from point i of pts kSlopeColumns on in direction d, or
  // nullopt where the track ends first.
  std::optional<double> Descent(const std::vector<int>& pts, int i, int d) const {
    const int ahead = i + d * kSlopeColumns;
    if (ahead < 0 || ahead >= static_cast<int>(pts.size())) return std::nullopt;
    return (ColumnPoint(net_, pts[ahead]).y - ColumnPoint(net_, pts[i]).y) / kSlopeColumns;
  }

  // The column track to go on in from `at`, where the line leans `lean` px
  // per row: within `reach`, descending the way it leans, unlike the
  // frame's segments; the least turn.
  std::optional<ColumnPlace> NextPiece(cv::Point2d at, double lean, double reach) {
    const int d = lean > 0 ? 1 : -1;
    std::optional<ColumnPlace> best;
    double least_turn = kMaxTurnDeg;
    const int y_at = static_cast<int>(at.y), reach_y = static_cast<int>(std::ceil(reach));
    for (int y = std::max(0, y_at - reach_y); y <= std::min(Rows() - 1, y_at + reach_y); ++y)
      for (int k = row_start_[y]; k < row_start_[y + 1]; ++k) {
        const ColumnPlace& c = places_[k];
        const std::vector<int>& pts = Pool(c.pool)[c.track].points;
        const cv::Point2d q = ColumnPoint(net_, pts[c.at]);
        const std::optional<double> descent = Descent(pts, c.at, d);
        if (used_[c.pool][c.track][c.at] || !descent || q.y < at.y - 1.0 ||
            std::hypot(q.x - at.x, q.y - at.y) > reach)
          continue;
        if (*descent < kMinDescent || std::abs(d * *descent - typical_) < kSegmentLike) continue;
        const double turn = std::abs(std::atan(lean) - std::atan(d / *descent)) * 180.0 / CV_PI;
        if (turn < least_turn) {
          least_turn = turn;
          best = c;
        }
      }
    return best;
  }

  // Follows the column track from `from` in direction d, appending its
  // points to *path, until it ends, turns into a segment or meets another
  // line (*stopped), or a line track other than a starts on it below row
  // y0 (*b). Returns the last point taken, or -1.
  int AlongPiece(const ColumnPlace& from, int a, int d, double y0, std::vector<cv::Point2d>* path,
                 int* b, bool* stopped) {
    const std::vector<int>& pts = Pool(from.pool)[from.track].points;
    int last = -1;
    for (int i = from.at; i >= 0 && i < static_cast<int>(pts.size()); i += d) {
      if (used_[from.pool][from.track][i]) break;
      if (const auto descent = Descent(pts, i, d);
          i != from.at && descent && *descent < kMinDescent) {
        *stopped = true;  // it turns into a segment
        break;
      }
      const cv::Point2d q = ColumnPoint(net_, pts[i]);
      if (q.y <= path->back().y) continue;
      if ((*b = StartsAt(q, a, y0)) >= 0) break;
      const int near = NearestLinePoint(net_, static_cast<int>(std::lround(q.y)), q.x - kOtherLine,
                                        q.x + kOtherLine, q.x);
      if (near >= 0 && net_.line_of_point[near] != a) {
        *stopped = true;  // it meets another line
        break;
      }
      path->push_back(q);
      last = i;
    }
    return last;
  }

  // A line track other than a starting within steep_reach of q below row
  // y0, and continuing no other, or -1.
  int StartsAt(cv::Point2d q, int a, double y0) const {
    const int qy = static_cast<int>(std::lround(q.y));
    const int reach = static_cast<int>(std::ceil(params_.steep_reach));
    for (int y = std::max(0, qy - reach); y <= std::min(Rows() - 1, qy + reach); ++y)
      for (int t : starting_[y]) {
        const cv::Point2d first = RowPoint(net_.lines[t].points.front());
        if (t != a && net_.line_above[t] < 0 && first.y > y0 &&
            std::hypot(first.x - q.x, first.y - q.y) <= params_.steep_reach)
          return t;
      }
    return -1;
  }

  const TrackParams& params_;
  TrackNetwork& net_;
  const double typical_;
  // The column points of both pools by image row: row y's are
  // places_[row_start_[y] .. row_start_[y + 1]).
  std::vector<int> row_start_;
  std::vector<ColumnPlace> places_;
  std::vector<std::vector<int>> starting_;  // line tracks by their first row
  std::vector<std::vector<char>> used_[2];  // per pool, track and point: followed
};

// Follows every line track that leans past max_step (LeaningLines).
void FollowLeaningLines(const TrackParams& params, const Cancellation& cancel, TrackNetwork* net) {
  LeaningLines leaning(params, net);
  for (int a = 0; a < static_cast<int>(net->lines.size()); ++a) {
    if (a % 1024 == 0) cancel.ThrowIfRequested("the leaning lines");
    leaning.Follow(a);
  }
  leaning.RemoveFollowedPieces();
}

// The x of line a's path below at row y (within its rows).
double PathX(const TrackNetwork& net, int a, double y) {
  const std::vector<cv::Point2d>& path = net.path_below[a];
  const auto after = std::partition_point(path.begin() + 1, path.end() - 1,
                                          [y](const cv::Point2d& q) { return q.y <= y; });
  const cv::Point2d& p1 = *after;
  const cv::Point2d& p0 = *std::prev(after);
  return p1.y == p0.y ? p0.x : p0.x + (p1.x - p0.x) * (y - p0.y) / (p1.y - p0.y);
}

// A bridged gap crossing a row: its path's x half a row down, and the line
// track above the gap.
struct GapAtRow {
  double x;
  int a;
};

// The bridged gaps by row: gap a (its path from line a's last point to
// the first of line_below[a]) is listed at every row from its upper end to
// the row before its lower end, with its x half a row down; each row's by
// that x.
std::vector<std::vector<GapAtRow>> GapsByRow(const TrackNetwork& net) {
  std::vector<std::vector<GapAtRow>> gaps_at(
      net.rows.row_start.empty() ? 0 : net.rows.row_start.size() - 1);
  for (int a = 0; a < static_cast<int>(net.lines.size()); ++a) {
    const std::vector<cv::Point2d>& path = net.path_below[a];
    if (path.empty()) continue;
    for (int y = static_cast<int>(path.front().y); y + 0.5 < path.back().y; ++y)
      gaps_at[y].push_back({PathX(net, a, y + 0.5), a});
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
    const std::vector<cv::Point2d>& path = net.path_below[a];
    if (ey <= path.front().y || ey >= path.back().y) continue;
    const double x = PathX(net, a, ey);
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

// Whether line tracks t and u are one line: the same track, or joined
// across gaps (line_below) through a few tracks.
bool OneLine(const TrackNetwork& net, int t, int u) {
  constexpr int kHops = 4;
  for (const auto& [from, to] : {std::pair{t, u}, std::pair{u, t}}) {
    int k = from;
    for (int hops = 0; k >= 0 && hops <= kHops; ++hops, k = net.line_below[k])
      if (k == to) return true;
  }
  return false;
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
    // (a speck of light beside it, or a piece of that line where it leans
    // between two of its tracks) makes no junction.
    if (net->junctions.size() == first_junction + 2 &&
        OneLine(*net, net->junctions[first_junction].line, net->junctions[first_junction + 1].line))
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
  if (!(steep_reach > 0)) return fail("steep_reach must be positive");
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
    int length = 0;
    for (int k = i; k >= 0; k = next[k]) ++length;
    if (length < params.min_track) continue;
    Track t;
    t.points.reserve(static_cast<size_t>(length));
    for (int k = i; k >= 0; k = next[k]) t.points.push_back(k);
    if (track_of_point)
      for (int k : t.points) (*track_of_point)[k] = static_cast<int>(tracks.size());
    tracks.push_back(std::move(t));
  }
  return tracks;
}

std::vector<Track> CutSteepStretches(const extraction::RidgePoints& columns,
                                     std::vector<Track> segments, const TrackParams& params,
                                     const Cancellation& cancel, std::vector<Track>* steep_out) {
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
      const char is_steep = steep[i];
      Track piece;
      for (; i < n && steep[i] == is_steep; ++i) piece.points.push_back(t.points[i]);
      if (static_cast<int>(piece.points.size()) < params.min_track) continue;
      if (!is_steep)
        out.push_back(std::move(piece));
      else if (steep_out)
        steep_out->push_back(std::move(piece));
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
      cancel, &net.steep);
  cancel.ThrowIfRequested("the segment tracks");

  BridgeLineGaps(params, &net);
  cancel.ThrowIfRequested("the bridges across line gaps");
  FollowLeaningLines(params, cancel, &net);
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
