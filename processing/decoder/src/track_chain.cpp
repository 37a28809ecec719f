#include "track_chain.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <opencv2/imgproc.hpp>
#include <optional>
#include <set>
#include <tuple>
#include <vector>

#include "bsls/extraction/stripe_centre.h"
#include "bsls/extraction/stripe_pitch.h"
#include "bsls/geometry/curve_fit.h"
#include "junction_placement.h"
#include "working_resolution.h"

namespace bsls::decoder::internal {
namespace {

using geometry::FitAtZero;
using geometry::FitLine;
using geometry::FitParabola;
using geometry::Sample;
using geometry::Samples;

using Clock = std::chrono::steady_clock;

double MsSince(Clock::time_point t) {
  return std::chrono::duration<double, std::milli>(Clock::now() - t).count();
}

// The sub-pixel centres of one line track, by row (NaN where none).
struct TrackCentres {
  int first_row = 0;
  std::vector<double> measured;  // centres measured and kept
  std::vector<double> output;    // measured, or refilled between measured ones

  double Measured(int y) const {
    const int i = y - first_row;
    return i >= 0 && i < static_cast<int>(measured.size()) ? measured[i] : NAN;
  }
};

// The (t = row - y, centre) samples of the measured centres within `reach`
// rows of y, into `s` (reused by the caller, so that it is allocated once).
void MeasuredNear(const TrackCentres& c, int y, int reach, bool skip_own, Samples* s) {
  s->clear();
  for (int r = y - reach; r <= y + reach; ++r) {
    if (skip_own && r == y) continue;
    const double x = c.Measured(r);
    if (!std::isnan(x)) s->emplace_back(r - y, x);
  }
}

// The centres of line track `t`: measured in each row clear of the track's
// junctions, those far from their ridge points dropped, and the rows beside
// junctions refilled from the centres on both sides.
TrackCentres MeasureTrack(const cv::Mat& grey, const interpretation::TrackNetwork& net, int t,
                          const DecodeParams& params) {
  const TrackChainParams& tp = params.track_chain;
  const auto& pts = net.lines[t].points;
  const auto& rp = net.rows.points;
  TrackCentres c;
  c.first_row = rp[pts.front()].y;
  const int n = static_cast<int>(pts.size());
  c.measured.assign(n, NAN);
  const int clearance = params.junction_clearance;
  std::vector<char> beside_junction(n, 0);
  for (int j : net.junctions_on_line[t]) {
    const int jy = static_cast<int>(std::lround(net.junctions[j].position.y));
    for (int y = jy - clearance; y <= jy + clearance; ++y)
      if (y - c.first_row >= 0 && y - c.first_row < n) beside_junction[y - c.first_row] = 1;
  }
  for (int i = 0; i < n; ++i) {
    if (beside_junction[i]) continue;
    const extraction::RidgePoint& p = rp[pts[i]];
    // A centre far from its ridge point took another stripe's light (a
    // neighbour crowding in, a segment nearby): dropped.
    const auto x = extraction::RidgeCentreInRow(grey, p.y, p.x);
    if (x && std::abs(*x - p.x) <= tp.max_centre_shift) c.measured[i] = *x;
  }
  // A centre its neighbours' curve misses by more than max_centre_residual
  // took a segment's or a shadow's light (the row next to a skipped junction
  // most): dropped, and refilled below where it lies in a short gap.
  Samples near;
  std::vector<double> kept = c.measured;
  for (int i = 0; i < n; ++i) {
    if (std::isnan(c.measured[i])) continue;
    MeasuredNear(c, c.first_row + i, tp.residual_rows, true, &near);
    if (near.size() < 3) continue;
    const std::optional<double> expected = FitAtZero(near);
    if (expected && std::abs(*expected - c.measured[i]) > tp.max_centre_residual) kept[i] = NAN;
  }
  c.measured.swap(kept);
  // Refill: each run of rows without a centre (the rows beside a junction,
  // and a centre or two dropped next to them) from one parabola through the
  // measured centres within centre_fit_rows on both sides of it.
  const int reach = tp.centre_fit_rows;
  const int longest = 2 * clearance + 3;
  c.output = c.measured;
  for (int g0 = 0; g0 < n;) {
    if (!std::isnan(c.measured[g0])) {
      ++g0;
      continue;
    }
    int g1 = g0;
    while (g1 + 1 < n && std::isnan(c.measured[g1 + 1])) ++g1;
    const int gap_start = g0;
    g0 = g1 + 1;
    if (gap_start == 0 || g1 == n - 1 || g1 - gap_start + 1 > longest) continue;
    const double middle = 0.5 * (gap_start + g1);
    near.clear();
    for (int i = std::max(gap_start - reach, 0); i <= std::min(g1 + reach, n - 1); ++i)
      if (!std::isnan(c.measured[i])) near.emplace_back(i - middle, c.measured[i]);
    geometry::Quadratic q;
    double a, b;
    if (FitParabola(near, &q)) {
      for (int i = gap_start; i <= g1; ++i)
        c.output[i] = q[0] + (i - middle) * (q[1] + (i - middle) * q[2]);
    } else if (FitLine(near, &a, &b)) {
      for (int i = gap_start; i <= g1; ++i) c.output[i] = a + b * (i - middle);
    }
  }
  return c;
}

// Drops the output centres of line track t that do not belong to its line
// p: where a junction of the track not labelled p lies beyond its last (or
// before its first) junction of p, the track went on across an occluding
// edge into another line or into a region whose labels could not be
// proven, and its centres from half a row spacing past its last junction
// of p (or that junction, if nearer) on are dropped. A junction not
// labelled p between two of p is a stray segment end and cuts nothing, so
// is one beyond the track's last junction of p where the track across the
// gap below holds junctions of p (and the same above: the lips' fold on
// line 0, where the line breaks at an unproven junction and goes on), and
// a track that runs on with no junction keeps its centres. The measured
// centres stay: they still place the line's junctions.
void KeepRowsOfItsLine(const interpretation::TrackNetwork& net,
                       const interpretation::TrackLabels& labels, int t, TrackCentres* c) {
  const int p = labels.line_p[t];
  const double reach = labels.row_spacing > 0 ? 0.5 * labels.row_spacing : 0.0;
  auto holds_p = [&](int track) {
    if (track < 0 || labels.line_p[track] != p) return false;
    const std::vector<int>& on = net.junctions_on_line[track];
    return std::any_of(on.begin(), on.end(), [&](int j) { return labels.p[j] == p; });
  };
  // The line goes on as p across its gap below (above): a junction not
  // labelled p between there and the track's own junctions of p lies
  // between two of p.
  const bool p_below = holds_p(net.line_below[t]);
  const bool p_above = holds_p(net.line_above[t]);
  double first = INFINITY, last = -INFINITY;  // rows of its junctions of p
  const std::vector<int>& on = net.junctions_on_line[t];
  for (int j : on)
    if (labels.p[j] == p) {
      first = std::min(first, net.junctions[j].position.y);
      last = std::max(last, net.junctions[j].position.y);
    }
  double from = -INFINITY, to = INFINITY;
  for (int j : on) {
    if (labels.p[j] == p) continue;
    const double y = net.junctions[j].position.y;
    if (y > last && !p_below) to = std::min(to, std::min(y, last + reach));
    if (y < first && !p_above) from = std::max(from, std::max(y, first - reach));
  }
  for (size_t k = 0; k < c->output.size(); ++k) {
    const double y = c->first_row + static_cast<double>(k);
    if (y < from || y > to) c->output[k] = NAN;
  }
}

// The measured centres of `line` within `reach` rows of row y0, as
// (row - y0, x) pairs.
std::vector<std::pair<double, double>> CentresNear(const TrackCentres& line, double y0, int reach) {
  std::vector<std::pair<double, double>> out;
  for (int r = static_cast<int>(std::ceil(y0 - reach)); r <= y0 + reach; ++r)
    if (const double x = line.Measured(r); !std::isnan(x)) out.emplace_back(r - y0, x);
  return out;
}

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
                          const ColumnCentres& measured, const DecodeParams& params) {
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
  if (double c, e; plan.ok && FitMeasuredSegment(plan, measured, params, &c, &e)) {
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

// The line and segment tracks' ridge points drawn on a CV_8UC1 image of
// the full frame's `size` (0/255); found on a resampled frame, each track as
// a polyline through its points' full-frame pixels. Asks `cancel` every
// thousand tracks.
cv::Mat DrawTracks(const interpretation::TrackNetwork& net, const WorkingScale& scale,
                   cv::Size size, const Cancellation& cancel) {
  cv::Mat out = cv::Mat::zeros(size, CV_8UC1);
  std::vector<cv::Point> path;
  int drawn = 0;
  auto draw = [&](const std::vector<interpretation::Track>& tracks,
                  const extraction::RidgePoints& points, bool transposed) {
    for (const interpretation::Track& track : tracks) {
      if (++drawn % 1024 == 0) cancel.ThrowIfRequested("drawing the tracks");
      if (scale.IsIdentity()) {  // each point on its own pixel, next to its neighbours
        for (int k : track.points) {
          const extraction::RidgePoint& p = points.points[k];
          const int x = static_cast<int>(std::lround(p.x));
          out.at<uchar>(transposed ? x : p.y, transposed ? p.y : x) = 255;
        }
        continue;
      }
      path.clear();
      for (int k : track.points) {
        const extraction::RidgePoint& p = points.points[k];
        const cv::Point2d at =
            scale.ToFull(transposed ? cv::Point2d(p.y, p.x) : cv::Point2d(p.x, p.y));
        path.emplace_back(static_cast<int>(std::lround(at.x)), static_cast<int>(std::lround(at.y)));
      }
      cv::polylines(out, path, false, cv::Scalar(255), 1, cv::LINE_8);
    }
  };
  draw(net.lines, net.rows, false);
  draw(net.segments, net.columns, true);  // a column point's x is its row
  return out;
}

// A line's centres on the working frame (one per working row, ordered by y)
// as one per row of the full frame: each mapped to the full frame and the
// full rows between two consecutive working rows interpolated linearly; no
// row is filled across a working row without a centre.
std::vector<cv::Point2d> RowsOfFullFrame(const std::vector<cv::Point2d>& working,
                                         const WorkingScale& scale) {
  std::vector<cv::Point2d> out;
  for (size_t k = 0; k < working.size(); ++k) {
    const cv::Point2d a = scale.ToFull(working[k]);
    const bool joined = k + 1 < working.size() && working[k + 1].y - working[k].y == 1.0;
    if (!joined) {
      if (a.y == std::floor(a.y)) out.push_back(a);  // on a full row of its own
      continue;
    }
    const cv::Point2d b = scale.ToFull(working[k + 1]);
    for (int y = static_cast<int>(std::ceil(a.y)); y < b.y; ++y)
      out.emplace_back(a.x + (b.x - a.x) * (y - a.y) / (b.y - a.y), y);
  }
  return out;
}

// The track chain's working frame and the ridge points found on it.
struct WorkingRidges {
  cv::Mat working;     // the frame resampled (WorkingFactor)
  WorkingScale scale;  // its pixels to the full frame's
  extraction::RidgePoints rows;
  extraction::RidgePoints columns;
};

// The working resolution: the frame resampled so that its stripes lie
// about as far apart as the pixel sizes are tuned for, smoothed, and its
// ridge points along rows and columns found, into *out. Sets result's
// pitch, scale, binning, region and extraction time; false (with
// result->error) where the frame shows no stripe pattern.
bool FindWorkingRidges(const cv::Mat& grey, const DecodeParams& params, const Cancellation& cancel,
                       DecodeResult* result, WorkingRidges* out) {
  const TrackChainParams& tp = params.track_chain;
  const auto t = Clock::now();
  if (params.binning == 0) {
    result->pitch = extraction::MeasureStripePitch(grey, params.pitch).value_or(0.0);
    // Without a regular spacing of stripes there is no pattern to label
    // (noise, a blank or a covered slide): whatever the tracks would find
    // there is not a label.
    if (result->pitch == 0.0) {
      result->error =
          "no stripe pattern: the frame's central rows show no regular spacing of stripes";
      return false;
    }
  }
  cancel.ThrowIfRequested("the stripe pitch");
  const double factor = WorkingFactor(result->pitch, params);
  out->scale = ResampleFrame(grey, factor, &out->working);
  result->scale = factor;
  result->binning = std::max(1, static_cast<int>(std::lround(factor)));
  result->region = cv::Rect(0, 0, grey.cols, grey.rows);
  cv::Mat smoothed;
  cv::GaussianBlur(out->working, smoothed, cv::Size(0, 0), tp.smoothing_sigma, tp.smoothing_sigma,
                   cv::BORDER_REPLICATE);
  cancel.ThrowIfRequested("the smoothing");
  out->rows = extraction::FindRidgePoints(smoothed, tp.ridge, cancel);
  cancel.ThrowIfRequested("the ridges along rows");
  out->columns = extraction::FindColumnRidgePoints(smoothed, tp.ridge, cancel);
  cancel.ThrowIfRequested("the ridges along columns");
  result->times.extraction_ms = MsSince(t);
  return true;
}

// The labelled line tracks (those with a p), in index order.
std::vector<int> LabelledTracks(const interpretation::TrackLabels& labels) {
  std::vector<int> labelled;
  for (size_t i = 0; i < labels.line_p.size(); ++i)
    if (labels.line_p[i] >= 0) labelled.push_back(static_cast<int>(i));
  return labelled;
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

// The centres of line track t's line below its last row where it leans
// past the row tracks' reach (a steep stretch carries it on: across a gap
// to the track below, or to its end): each stretch's point measured across
// the stripe in its column (RidgeCentreInColumn), and the line's x at every
// row down to the track below (or the stretch's end) read off those, as
// (x, y) in the working frame. Empty for a chord across a gap, or where
// the rows beside the stretch have no centre (cut at an edge).
std::vector<cv::Point2d> SteepCentres(const cv::Mat& working,
                                      const interpretation::TrackNetwork& net,
                                      const std::vector<TrackCentres>& centres, int t) {
  const int b = net.line_below[t];
  const std::vector<cv::Point2d>& path = net.path_below[t];
  const std::vector<double>& above = centres[t].output;
  // The track's last centre, a few rows before its end at most (the last
  // rows of a leaning line measure badly across the row).
  int last = static_cast<int>(above.size()) - 1;
  while (last >= 0 && std::isnan(above[last]) && static_cast<int>(above.size()) - last <= 3) --last;
  if (path.size() <= 2 || last < 0 || std::isnan(above[last]) ||
      (b >= 0 && (centres[b].output.empty() || std::isnan(centres[b].output.front()))))
    return {};
  std::vector<cv::Point2d> measured;
  measured.emplace_back(above[last], centres[t].first_row + last);
  for (size_t k = 1; k < path.size(); ++k) {
    if (b >= 0 && k + 1 == path.size()) break;  // the track below's first point
    const int x = static_cast<int>(std::lround(path[k].x));
    const auto y = extraction::RidgeCentreInColumn(working, x, path[k].y);
    if (y && std::abs(*y - path[k].y) <= 1.0 && *y > measured.back().y)
      measured.emplace_back(x, *y);
  }
  if (b >= 0) {
    const cv::Point2d end(centres[b].output.front(), centres[b].first_row);
    if (end.y <= measured.back().y) return {};
    measured.push_back(end);
  }
  std::vector<cv::Point2d> out;
  size_t k = 0;
  for (int y = static_cast<int>(measured.front().y) + 1; y < measured.back().y; ++y) {
    while (measured[k + 1].y < y) ++k;
    const cv::Point2d &p0 = measured[k], &p1 = measured[k + 1];
    out.emplace_back(p0.x + (p1.x - p0.x) * (y - p0.y) / (p1.y - p0.y), y);
  }
  return out;
}

// Lines: the centres of all tracks of one p, one per row of the working
// frame (`rows` of them; the first labelled track's where two hold one
// row), with the rows where a steep stretch carries a track of p on
// (SteepCentres), in the full frame.
std::vector<DecodedLine> DecodedLines(const cv::Mat& working,
                                      const interpretation::TrackNetwork& net,
                                      const std::vector<int>& labelled,
                                      const interpretation::TrackLabels& labels,
                                      const std::vector<TrackCentres>& centres, int rows,
                                      const WorkingScale& scale) {
  std::vector<DecodedLine> lines;
  int max_p = -1;
  for (int i : labelled) max_p = std::max(max_p, labels.line_p[i]);
  std::vector<double> row_x;
  for (int p = 0; p <= max_p; ++p) {
    row_x.assign(rows, NAN);
    bool any = false;
    for (int i : labelled) {
      if (labels.line_p[i] != p) continue;
      const TrackCentres& c = centres[i];
      for (size_t k = 0; k < c.output.size(); ++k) {
        double& x = row_x[c.first_row + k];
        if (std::isnan(x) && !std::isnan(c.output[k])) {
          x = c.output[k];
          any = true;
        }
      }
    }
    for (int i : labelled) {
      const int below = net.line_below[i];
      if (labels.line_p[i] != p || (below >= 0 && labels.line_p[below] != p)) continue;
      for (const cv::Point2d& c : SteepCentres(working, net, centres, i)) {
        double& x = row_x[static_cast<int>(c.y)];
        if (std::isnan(x)) x = c.x;
      }
    }
    if (!any) continue;
    DecodedLine& line = lines.emplace_back(DecodedLine{p, {}});
    for (int y = 0; y < rows; ++y)
      if (!std::isnan(row_x[y])) line.points.emplace_back(row_x[y], y);
  }
  if (!scale.IsIdentity())
    for (DecodedLine& line : lines) line.points = RowsOfFullFrame(line.points, scale);
  return lines;
}

// The labelled junctions of the network, one per label (JunctionPerLabel),
// placed (thesis 5.2) in the full frame: planned, their segments' columns
// measured once each, and placed, each step in parallel.
std::vector<DecodedJunction> PlaceTrackJunctions(const cv::Mat& working,
                                                 const interpretation::TrackNetwork& net,
                                                 const interpretation::TrackLabels& labels,
                                                 const std::vector<TrackCentres>& centres,
                                                 const DecodeParams& params,
                                                 const WorkingScale& scale, int* conflicts) {
  const std::vector<int> placed = JunctionPerLabel(net, labels, conflicts);
  const cv::Range all(0, static_cast<int>(placed.size()));
  std::vector<JunctionPlan> plans(placed.size());
  cv::parallel_for_(all, [&](const cv::Range& r) {
    for (int i = r.start; i < r.end; ++i)
      plans[i] = PlanTrackJunction(net, placed[i], centres[net.junctions[placed[i]].line], params);
  });
  ColumnCentres columns = ColumnCentres::Wanted(plans);
  cv::parallel_for_(cv::Range(0, static_cast<int>(columns.keys.size())), [&](const cv::Range& r) {
    for (int i = r.start; i < r.end; ++i) {
      const auto [x, y] = columns.keys[i];
      columns.centres[i] = extraction::RidgeCentreInColumn(working, x, y);
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
        at = RefineJunction(plans[i], columns, net.junctions[j].position.y, params, 1);
      if (!at)
        at = PlaceJunction(working, net, j, centres[net.junctions[j].line], plans[i], columns,
                           params);
      d.position = scale.ToFull(*at);
    }
  });
  return junctions;
}

// Whether verdict k of a geometry's per-junction list rules its junction
// out; a geometry that judges no junction one by one (a shorter list) rules
// none out.
bool RuledOut(const std::vector<char>& verdicts, size_t k) {
  return k < verdicts.size() && verdicts[k];
}

// Issue 25 parts 3-4 (docs/decoding.md, "Islands placed by the geometry"):
// the calibration's `geometry` judges line 0's component first: where it
// clearly puts the component at another shift (the track taken for line 0
// was another line in phase with it), the component moves there, or, off
// the slide, the frame is refused; its junctions the geometry rules out lose
// their labels. Then each island of `labels` takes the shift the geometry
// proves for it, less the junctions it rules out and those whose labels
// another junction already holds (a slide junction is seen once); where those
// are more than a tenth of the island, or any label would fall off the slide
// or disagree with its kind, the island stays unlabelled. Counts the islands
// placed and the component's move in `result`. With `may_move` false, a
// component the geometry does not confirm where it stands is refused.
void PlaceByGeometry(const interpretation::TrackNetwork& net, const pattern::PatternSpec& spec,
                     const WorkingScale& scale, const LabelGeometry& geometry, bool may_move,
                     interpretation::TrackLabels* labels, DecodeResult* result) {
  constexpr double kMaxDropped = 0.1;
  constexpr double kMaxRefuted = 1.0 / 3.0;
  std::vector<FramedJunction> labelled;
  std::vector<int> index;
  for (int j = 0; j < static_cast<int>(net.junctions.size()); ++j)
    if (labels->p[j] != interpretation::kUnlabelled) {
      labelled.push_back({scale.ToFull(net.junctions[j].position), labels->p[j], labels->v[j]});
      index.push_back(j);
    }
  auto on_slide = [&](int j, int p, int v) {
    return pattern::JunctionOnRowParity(spec, p, v) == net.junctions[j].kind;
  };
  auto lines_on_slide = [&](const std::vector<int>& line_p, int dp) {
    return std::all_of(line_p.begin(), line_p.end(),
                       [&](int lp) { return lp + dp >= 0 && lp + dp < spec.lines; });
  };

  std::string why;
  const auto own = geometry.PlaceIsland(labelled, labelled, &why);
  const bool moves = own && (own->dp != 0 || own->dq != 0);
  if (!may_move && (!own || moves)) {
    labels->ok = false;
    labels->error = own ? "the calibration's geometry puts the labels " + std::to_string(own->dp) +
                              " lines and " + std::to_string(own->dq) + " rows off"
                        : "the calibration's geometry cannot confirm the labels: " + why;
    return;
  }
  if (moves) {
    std::vector<int> line_p;
    for (int lp : labels->line_p)
      if (lp >= 0) line_p.push_back(lp);
    bool fits = lines_on_slide(line_p, own->dp);
    for (size_t k = 0; k < index.size() && fits; ++k)
      fits = on_slide(index[k], labelled[k].p + own->dp, labelled[k].q + own->dq);
    if (!fits) {
      labels->ok = false;
      labels->error = "the calibration's geometry puts the labels " + std::to_string(own->dp) +
                      " lines off, off the slide: the line taken for line 0 is not line 0";
      return;
    }
    for (size_t k = 0; k < index.size(); ++k) {
      labels->p[index[k]] += own->dp;
      labels->v[index[k]] += own->dq;
      labelled[k].p += own->dp;
      labelled[k].q += own->dq;
    }
    for (int& lp : labels->line_p)
      if (lp >= 0) lp += own->dp;
    result->line_zero_moved = own->dp;
  }
  // A label the geometry rules out is not reported; where it rules out more
  // than a third of the component, the component's labels are refuted.
  const std::vector<char> out = geometry.RuleOut(labelled);
  const auto refuted = std::count(out.begin(), out.end(), 1);
  if (refuted > kMaxRefuted * static_cast<double>(labelled.size())) {
    labels->ok = false;
    labels->error = "the calibration's geometry refutes the labels: " + std::to_string(refuted) +
                    " of " + std::to_string(labelled.size()) +
                    " junctions of line 0's part are off their rows";
    return;
  }
  std::vector<FramedJunction> kept;
  for (size_t k = 0; k < index.size(); ++k) {
    if (RuledOut(out, k)) {
      labels->p[index[k]] = labels->v[index[k]] = interpretation::kUnlabelled;
      ++result->ruled_out;
    } else {
      kept.push_back(labelled[k]);
    }
  }
  labelled = std::move(kept);
  std::set<std::pair<int, int>> taken;
  for (const FramedJunction& j : labelled) taken.emplace(j.p, j.q);
  for (const interpretation::TrackLabels::Island& island : labels->islands) {
    std::vector<FramedJunction> members;
    for (size_t k = 0; k < island.junctions.size(); ++k)
      members.push_back(
          {scale.ToFull(net.junctions[island.junctions[k]].position), island.p[k], island.v[k]});
    const std::optional<LabelShift> shift = geometry.PlaceIsland(labelled, members, &why);
    if (!shift || !lines_on_slide(island.line_p, shift->dp)) continue;
    std::vector<char> keep(island.junctions.size(), 0);
    bool fits = true;
    size_t dropped = 0;
    for (size_t k = 0; k < island.junctions.size() && fits; ++k) {
      const int p = island.p[k] + shift->dp, v = island.v[k] + shift->dq;
      fits = on_slide(island.junctions[k], p, v);
      keep[k] = !RuledOut(shift->ruled_out, k) && !taken.contains({p, v});
      dropped += !keep[k];
    }
    if (!fits || dropped > kMaxDropped * static_cast<double>(island.junctions.size())) continue;
    for (size_t k = 0; k < island.junctions.size(); ++k) {
      if (!keep[k]) continue;
      labels->p[island.junctions[k]] = island.p[k] + shift->dp;
      labels->v[island.junctions[k]] = island.v[k] + shift->dq;
    }
    result->ruled_out += static_cast<int>(dropped);
    for (size_t k = 0; k < island.lines.size(); ++k)
      labels->line_p[island.lines[k]] = island.line_p[k] + shift->dp;
    ++result->islands_placed;
  }
}

// Labels with a calibration: line 0's chain of candidates nearest the
// centre row (thesis 5.2.1), its component judged by the geometry
// (PlaceByGeometry). Where that fails, the other chains are tried in turn
// (track_chain.reference_tries), each kept only where the geometry confirms
// its labels where they stand: a line whose inner neighbours are hidden
// looks like line 0 in the image, but not in depth. The first chain's
// failure is the one reported.
interpretation::TrackLabels LabelWithGeometry(const interpretation::TrackNetwork& net,
                                              pattern::Side side, const DecodeParams& params,
                                              const WorkingScale& scale,
                                              const LabelGeometry& geometry,
                                              const Cancellation& cancel, DecodeResult* result) {
  interpretation::TrackLabellingParams lp = params.track_chain.labelling;
  // The geometry checks every junction's row: one row count across a gap
  // joins a part of line 0 (TrackLabellingParams::min_seeded_half_votes).
  lp.min_seeded_half_votes = 1;
  interpretation::TrackLabels first;
  for (int choice = 0; choice <= params.track_chain.reference_tries; ++choice) {
    lp.reference_choice = choice;
    interpretation::TrackLabels labels =
        interpretation::LabelTracks(net, side, params.spec, lp, cancel);
    if (labels.ok) {
      DecodeResult placed;
      PlaceByGeometry(net, params.spec, scale, geometry, /*may_move=*/choice == 0, &labels,
                      &placed);
      if (labels.ok) {
        result->line_zero_moved = placed.line_zero_moved;
        result->ruled_out += placed.ruled_out;
        result->islands_placed += placed.islands_placed;
        result->reference_choice = choice;
        return labels;
      }
    }
    cancel.ThrowIfRequested("the labelling");
    const bool more = choice + 1 < labels.reference_choices;
    if (choice == 0) first = std::move(labels);
    if (!more) break;
  }
  return first;
}

// The junctions as they leave the decoder, at their sub-pixel places: a
// label the geometry rules out there is taken back and the junction listed
// unlabelled (its place can differ from the track junction's judged before).
void RuleOutPlaced(const LabelGeometry& geometry, DecodeResult* result) {
  std::vector<FramedJunction> placed;
  for (const DecodedJunction& j : result->junctions) placed.push_back({j.position, j.p, j.q});
  const std::vector<char> out = geometry.RuleOut(placed);
  std::vector<DecodedJunction> kept;
  for (size_t k = 0; k < result->junctions.size(); ++k) {
    const DecodedJunction& j = result->junctions[k];
    if (RuledOut(out, k)) {
      result->unlabelled.push_back({j.position, j.kind});
      ++result->ruled_out;
    } else {
      kept.push_back(j);
    }
  }
  result->junctions = std::move(kept);
  SortByRow(&result->unlabelled);
}

}  // namespace

void DecodeByTracks(const cv::Mat& grey, pattern::Side side, const DecodeParams& params,
                    const Cancellation& cancel, DecodeResult* result) {
  const TrackChainParams& tp = params.track_chain;
  WorkingRidges ridges;
  if (!FindWorkingRidges(grey, params, cancel, result, &ridges)) return;
  const cv::Mat& working = ridges.working;
  const WorkingScale& scale = ridges.scale;

  auto t = Clock::now();
  const interpretation::TrackNetwork net = interpretation::BuildTrackNetwork(
      std::move(ridges.rows), std::move(ridges.columns), side, tp.tracks, cancel);
  interpretation::TrackLabels labels =
      params.geometry
          ? LabelWithGeometry(net, side, params, scale, *params.geometry, cancel, result)
          : interpretation::LabelTracks(net, side, params.spec, tp.labelling, cancel);
  result->times.interpretation_ms = MsSince(t);
  result->label_conflicts = labels.conflicts;
  cancel.ThrowIfRequested("the labelling");
  // The tracks' ridge points, as the skeleton chain's repaired skeleton.
  result->skeleton = DrawTracks(net, scale, grey.size(), cancel);
  if (!labels.ok) {
    result->error = labels.error;
    return;
  }
  result->islands = static_cast<int>(labels.islands.size());

  t = Clock::now();
  // Centres of every labelled line track, in parallel.
  const std::vector<int> labelled = LabelledTracks(labels);
  std::vector<TrackCentres> centres(net.lines.size());
  cv::parallel_for_(cv::Range(0, static_cast<int>(labelled.size())), [&](const cv::Range& r) {
    for (int i = r.start; i < r.end; ++i) {
      centres[labelled[i]] = MeasureTrack(working, net, labelled[i], params);
      KeepRowsOfItsLine(net, labels, labelled[i], &centres[labelled[i]]);
    }
  });

  result->junctions =
      PlaceTrackJunctions(working, net, labels, centres, params, scale, &result->label_conflicts);
  result->unlabelled = UnlabelledJunctions(net, labels, scale);
  if (params.geometry) RuleOutPlaced(*params.geometry, result);
  result->lines = DecodedLines(working, net, labelled, labels, centres, working.rows, scale);
  result->times.subpixel_ms = MsSince(t);
  result->ok = true;
}

}  // namespace bsls::decoder::internal
