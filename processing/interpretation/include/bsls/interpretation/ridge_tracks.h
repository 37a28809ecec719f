// The track network: ridge points (extraction/ridge_points.h) linked into
// the pattern's vertical lines and horizontal segments, and the T-junctions
// where a segment's end meets a line (thesis 5.1.4: direct when the segment
// leaves towards p + 1, corresponding when it comes from p - 1).
//
// Not the thesis's skeleton tracing (5.2): the lines come as tracks of one
// ridge point per row, the segments as tracks of one per column, so a
// junction is read off where a segment track ends beside a line track
// instead of being classified from a pixel graph. Where the light of a line
// and a segment overlaps, both tracks usually run on through the junction;
// where it does not, a segment's end stops a few pixels short of its line.
// Either way the end lies within `end_reach` of the line.
//
// Image coordinates: x right, y down, pixels.
//
// Thread-safety: pure functions of their arguments.
#ifndef BSLS_INTERPRETATION_RIDGE_TRACKS_H_
#define BSLS_INTERPRETATION_RIDGE_TRACKS_H_

#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "bsls/common/cancellation.h"
#include "bsls/extraction/ridge_points.h"
#include "bsls/pattern/brick_pattern.h"

namespace bsls::interpretation {

struct TrackParams {
  // px: a ridge point links to the nearest point of the next row within
  // this (the steepest line followed: about 50 degrees from the vertical), > 0.
  double max_step = 1.2;
  int min_track = 4;    // points: shorter tracks are noise, >= 1
  int min_segment = 3;  // points of a segment track that make junctions, >= 1
  // px: a segment's end meets a line whose ridge point lies this close to
  // it in the end's row (or the rows either side), > 0.
  double end_reach = 6.0;
  // The row where a segment's end meets its line is its end point's, or,
  // where that lies more than end_bend rows off a straight line through
  // end_fit of its points end_skip in from the end (a segment of end_skip + 2
  // points or more), the line's; >= 0, >= 2 and >= 0.
  int end_skip = 3;
  int end_fit = 6;
  double end_bend = 2.5;
  // A line track continues in another that starts at most bridge_rows rows
  // below its end and bridge_distance px from it, the two being each other's
  // nearest (a line broken where it turns too sharply for max_step, at a
  // fold, or cut by a shadow), >= 1 and > 0.
  int bridge_rows = 12;
  double bridge_distance = 8.0;
  // A segment track is cut where it climbs more than max_segment_slope rows
  // per column over steep_columns columns or more: there it follows a
  // steeply slanted line from one segment's end to the next row's segment
  // (at a fold); a segment itself runs nearly along its row. > 0 and >= 2.
  double max_segment_slope = 0.6;
  int steep_columns = 4;
  // px: a line track whose end lies this close to a steep stretch goes on
  // along it, into the line track that starts this close to it lower down
  // or to the stretch's lower end (a line leaning past max_step where a
  // surface turns away: the base of the nose, a lump's skirt), > 0.
  double steep_reach = 3.0;

  // True when the values are usable; otherwise says why.
  bool IsValid(std::string* error) const;
};

// Ridge points linked from row to row: indices into RidgePoints::points,
// one per row, in increasing row order.
struct Track {
  std::vector<int> points;
};

struct TrackJunction {
  int line = -1;              // the vertical line's track
  int segment = -1;           // the segment's track
  bool segment_left = false;  // the segment lies to the left of the line in the image
  pattern::JunctionKind kind = pattern::JunctionKind::kDirect;
  // Where the segment's end meets the line: the line's ridge point in that
  // row, or the point of the chord across a gap in the line.
  cv::Point2d position;
};

struct TrackNetwork {
  extraction::RidgePoints rows;  // ridge points along the rows: the lines' crossings
  // Ridge points along the columns (extraction::FindColumnRidgePoints): a point's
  // x is an image row, its y an image column.
  extraction::RidgePoints columns;
  std::vector<Track> lines;        // tracks through `rows`
  std::vector<Track> segments;     // tracks through `columns`
  std::vector<int> line_of_point;  // for each point of `rows`: its line track, or -1
  std::vector<TrackJunction> junctions;
  std::vector<std::vector<int>> junctions_on_line;  // per line track: its junctions by increasing y
  // Per line track: the track continuing it across a gap below / above it, or -1.
  std::vector<int> line_below;
  std::vector<int> line_above;
  // Per line track: where its line goes on below its last ridge point, in
  // image (x, y) by increasing y from that point: across its gap to the
  // first point of line_below (their chord, or the steep stretch followed
  // between them), or, with no line below, along a steep stretch where the
  // line leans past the row tracks' reach down to its end (a tail). Empty
  // when it goes on nowhere.
  std::vector<std::vector<cv::Point2d>> path_below;
  // The stretches cut out of the segment tracks (CutSteepStretches):
  // pieces of lines leaning too far for the row tracks.
  std::vector<Track> steep;
};

// Links ridge points from row to row into tracks: each point to the nearest
// point of the next row within max_step, each point taken at most once (by
// the nearer claimant); tracks shorter than min_track are dropped.
// `track_of_point` (optional) receives each point's track or -1. Asks
// `cancel` every few dozen rows (Cancelled naming `stage`).
std::vector<Track> LinkTracks(const extraction::RidgePoints& points, const TrackParams& params,
                              std::vector<int>* track_of_point = nullptr,
                              const Cancellation& cancel = {},
                              std::string_view stage = "the tracks");

// Cuts the stretches of `segments` (tracks through `columns`) that climb
// more than max_segment_slope rows per column over steep_columns or more;
// pieces shorter than min_track are dropped. The stretches cut go to
// `steep` (optional). Asks `cancel` every thousand segments.
std::vector<Track> CutSteepStretches(const extraction::RidgePoints& columns,
                                     std::vector<Track> segments, const TrackParams& params,
                                     const Cancellation& cancel = {},
                                     std::vector<Track>* steep = nullptr);

// Links both sets of ridge points and finds the junctions of the brick
// slide of `side`. Throws std::invalid_argument for invalid params and
// bsls::Cancelled when `cancel` asks to stop.
TrackNetwork BuildTrackNetwork(extraction::RidgePoints rows, extraction::RidgePoints columns,
                               pattern::Side side, const TrackParams& params = {},
                               const Cancellation& cancel = {});

}  // namespace bsls::interpretation

#endif  // BSLS_INTERPRETATION_RIDGE_TRACKS_H_
