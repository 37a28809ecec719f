#include "track_centres.h"

#include <algorithm>
#include <cmath>

#include "bsls/extraction/stripe_centre.h"

namespace bsls::decoder::internal {

using geometry::FitAtZero;
using geometry::FitLine;
using geometry::FitParabola;
using geometry::Samples;

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
  out.reserve(2 * static_cast<size_t>(reach) + 1);
  for (int r = static_cast<int>(std::ceil(y0 - reach)); r <= y0 + reach; ++r)
    if (const double x = line.Measured(r); !std::isnan(x)) out.emplace_back(r - y0, x);
  return out;
}

}  // namespace bsls::decoder::internal
