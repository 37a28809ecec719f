#include "track_lines.h"

#include <algorithm>
#include <cmath>

#include "bsls/extraction/stripe_centre.h"

namespace bsls::decoder::internal {

namespace {

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

}  // namespace

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

}  // namespace bsls::decoder::internal
