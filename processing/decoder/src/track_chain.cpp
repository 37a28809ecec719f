#include "track_chain.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <opencv2/imgproc.hpp>
#include <vector>

#include "bsls/extraction/stripe_pitch.h"
#include "missing_junctions.h"
#include "track_centres.h"
#include "track_geometry.h"
#include "track_junctions.h"
#include "track_lines.h"
#include "working_resolution.h"

namespace bsls::decoder::internal {
namespace {

using Clock = std::chrono::steady_clock;

// Working px: an unlabelled junction this near one placed from its line's
// junctions (PlaceMissingJunctions) is that junction.
constexpr double kSameJunction = 2.0;

double MsSince(Clock::time_point t) {
  return std::chrono::duration<double, std::milli>(Clock::now() - t).count();
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
  if (params.draw_tracks) result->skeleton = DrawTracks(net, scale, grey.size(), cancel);
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
  result->lines = DecodedLines(working, net, labelled, labels, centres, working.rows, scale);
  const interpretation::LabellingParams& missing = params.interpretation.labelling;
  if (missing.interpolate_missing)
    PlaceMissingJunctions(result->lines, params.spec, params.q_offset.value_or(0),
                          missing.max_interpolated_run, kSameJunction * scale.x, &result->junctions,
                          &result->unlabelled);
  if (params.geometry) RuleOutPlaced(*params.geometry, result);
  result->times.subpixel_ms = MsSince(t);
  result->ok = true;
}

}  // namespace bsls::decoder::internal
