// Single-shot decoding: one grey frame of the brick pattern in, labelled
// junctions and labelled sub-pixel centre lines out (contracts section 5).
//
// Stages: feature extraction (thesis chapter 4), interpretation (chapter 5:
// reference line, boundary and loop tracing, repair, labelling), then
// sub-pixel centres on the grey frame along every labelled line and junction
// positions where a line's and its segment's centres meet.
//
// Frame size: the pixel-sized parameters of extraction, interpretation and
// centres are tuned for stripes 10-21 px apart (the thesis's 512 x 512
// frames). The stripe pitch of each frame is measured first
// (extraction::MeasureStripePitch); a frame whose pitch is n >= 2 times
// tuned_pitch (rounded) is binned n x n for extraction and interpretation,
// whose results are mapped back onto the full frame, and the sub-pixel stage
// runs on the full frame with its pixel lengths multiplied by n
// (docs/decoding.md, "Frame size").
//
// Coordinates: image pixels, x = column, y = row, origin at the centre of the
// top-left pixel. Labels: p absolute (0 = reference line); q relative unless
// DecodeParams::q_offset is set (contracts section 2).
//
// Thread-safety: Decode is a pure function of its arguments. It runs on the
// calling thread and OpenCV's pool (cv::parallel_for_), and on one thread
// of its own while it interprets (DecodeParams::measure_ahead).
#ifndef BSLS_DECODER_DECODER_H_
#define BSLS_DECODER_DECODER_H_

#include <map>
#include <memory>
#include <opencv2/core.hpp>
#include <optional>
#include <string>
#include <vector>

#include "bsls/common/cancellation.h"
#include "bsls/decoder/label_geometry.h"
#include "bsls/extraction/feature_extraction.h"
#include "bsls/extraction/ridge_points.h"
#include "bsls/extraction/stripe_centre.h"
#include "bsls/extraction/stripe_pitch.h"
#include "bsls/interpretation/interpreter.h"
#include "bsls/interpretation/ridge_tracks.h"
#include "bsls/interpretation/track_labelling.h"
#include "bsls/pattern/brick_pattern.h"

namespace bsls::decoder {

// Which chain of stages turns the frame into labelled junctions.
enum class DecodeChain {
  // Feature extraction to a one-pixel skeleton (thesis chapter 4) and its
  // interpretation as a pixel graph (chapter 5): boundary and loop tracing,
  // repair, labelling.
  kSkeleton,
  // Ridge points along rows and columns linked into line and segment tracks,
  // junctions where a segment's end meets a line, labels spread through them
  // (docs/decoding.md, "The track chain").
  kTracks,
};

// The track chain's own stages (DecodeChain::kTracks).
struct TrackChainParams {
  // The pixel sizes below hold for stripe pitches from native_pitch_min to
  // native_pitch_max px (the thesis scenes they were tuned on span 10.4 to
  // 20.8 px): a frame whose measured pitch (DecodeParams::pitch) lies
  // outside is resampled by pitch / tuned_pitch, reduced by area averaging
  // up to DecodeParams::max_binning times or enlarged by cubic interpolation
  // down to min_scale (DecodeParams::binning forces a whole factor, for
  // tests and benchmarks). 0 < min <= tuned <= max.
  double tuned_pitch = 15.0;
  double native_pitch_min = 10.0;
  double native_pitch_max = 22.0;
  double min_scale = 1.0;        // (0, 1]
  double smoothing_sigma = 1.0;  // px, Gaussian applied before the ridge points, > 0
  extraction::RidgeParams ridge;
  interpretation::TrackParams tracks;
  interpretation::TrackLabellingParams labelling;
  // px: a line centre further than this from its ridge point (the peak of
  // the smoothed frame the track followed) is dropped: it took another
  // stripe's light, > 0.
  double max_centre_shift = 0.5;
  // px: a centre further than this from the curve through its track's
  // centres within residual_rows rows (itself left out) is dropped: it took
  // a segment's light beside a junction, > 0 and >= 2.
  double max_centre_residual = 0.35;
  int residual_rows = 4;
  // A row skipped beside a junction is refilled from the line's centres
  // within this many rows of the skipped ones on both sides, >= 1.
  int centre_fit_rows = 5;
  // Columns of a segment measured next to its junction to place it, >= 2.
  int segment_columns = 10;
  // With a calibration (DecodeParams::geometry): where the chain of line-0
  // candidates nearest the centre row fails (its line has inner segments:
  // line 0 hidden there on a turned face) or the geometry refutes it, up to
  // this many other chains are tried in turn, each kept only where the
  // geometry confirms its labels where they stand, >= 0.
  int reference_tries = 4;

  // True when every part is usable; otherwise says which and why.
  bool IsValid(std::string* error) const;
};

struct DecodeParams {
  pattern::PatternSpec spec;
  // The track chain: about 4x the cost of a blur and Canny at 512 x 512
  // against the skeleton chain's 26-30x (docs/benchmarks.md); the skeleton chain places
  // junctions closer and keeps more of steeply leaning lines
  // (docs/decoding.md, "Which chain").
  DecodeChain chain = DecodeChain::kTracks;
  TrackChainParams track_chain;
  // The skeleton chain's parameters from here to region_margin, but for
  // spec, junction_clearance, junction_fit_rows, fold_slope_change, pitch,
  // max_binning and binning, which the track chain reads as well.
  extraction::ExtractionParams extraction;
  interpretation::InterpretationParams interpretation;
  // Pixel lengths below and in `centre` are for the working resolution (see
  // tuned_pitch): on a binned frame they are multiplied by the binning.
  extraction::StripeCentreParams centre;
  int junction_fit_rows = 7;     // rows each side of a junction fitted to place it
  int segment_fit_columns = 50;  // columns of a segment measured to place its junction
  int junction_clearance = 3;    // px each side of a junction where the other stroke biases centres
  // px: a line centre further from its neighbours' fit is dropped.
  double max_centre_residual = 0.35;
  // Rows skipped beside a segment are refilled from the line's fit only where
  // the line is steeper than this (|dx/dy|) nowhere near...
  double max_fill_slope = 0.5;
  // ... or, where it is steeper, from a parabola through at least two
  // measured rows on each side that holds all of them within this RMS (px;
  // 0: steep stretches are never refilled).
  double steep_fill_residual = 0.05;
  // A line whose slope (dx/dy) above and below a junction differs by more
  // folds there; otherwise it is fitted as one smooth curve through it.
  double fold_slope_change = 0.5;
  // px: a fold's branches meeting the segment closer together than this meet
  // it at the fold's tip; farther apart, the junction is on one branch.
  double fold_tip_spread = 2.0;
  // px: lines whose skeletons pass closer than this in a row (a fold
  // squeezing them) are measured there together, one joint fit of their
  // stripes (extraction::StripeCentresInRow); 0: each on its own.
  double crowd_distance = 8.0;
  // Working resolution. The pixel-sized parameters (extraction,
  // interpretation, centre and the lengths above) hold for a stripe pitch
  // near tuned_pitch px: measured 10.4-20.8 px on the thesis scenes at
  // 512 x 512, where they were tuned. A frame whose measured pitch is wider
  // is binned n x n, n = round(pitch / tuned_pitch) (>= 1, <= max_binning),
  // for extraction and interpretation.
  extraction::StripePitchParams pitch;
  double tuned_pitch = 21.0;  // px, > 0
  int max_binning = 8;        // 1..16; 1 = never bin
  int binning = 0;            // 0 = from the measured pitch; 1..16 forces n (tests, benchmarks)
  // The columns beside the lit pattern are left out of extraction and
  // interpretation: those more than region_margin working px beyond every
  // 4 x 4 block whose mean rises region_rise grey levels above the frame's
  // dark ground (its 5th percentile). 0 keeps the whole frame. The margin
  // spans the stripe detector's reach (max_scale 4 px smoothing, the 27 px
  // contrast window).
  double region_rise = 6.0;  // grey levels, >= 0
  int region_margin = 32;    // working px, >= 0
  // The skeleton chain: where OpenCV has a second thread
  // (cv::getNumThreads() > 1) and the frame is not binned, the sub-pixel centres across the
  // extraction's skeleton runs are measured on a thread of their own while the interpretation runs
  // (docs/decoding.md, "Centres measured ahead"); the output is the same
  // either way. Off where the caller already keeps every core busy (both
  // sides of a session decoded side by side).
  bool measure_ahead = true;
  // A frame whose 1st-99th percentile range is narrower (grey levels) is blank.
  double min_dynamic_range = 16.0;
  // A frame with a larger fraction of pixels at 254-255 is saturated.
  double max_saturated_fraction = 0.4;
  // Even offset added to every q to make it the slide row; known only from a
  // calibration (slide-1 views). Unset: q is relative (thesis point O).
  std::optional<int> q_offset;
  // A calibrated side's geometry (label_geometry.h): the track chain asks it
  // to place the parts not joined to line 0 (islands). Unset: they stay
  // unlabelled.
  std::shared_ptr<const LabelGeometry> geometry;
  // The track chain draws its tracks into DecodeResult::skeleton (the
  // `--skeleton` image) only when asked: nothing downstream reads it, and
  // drawing every track costs 2 % of a decode. The skeleton chain's comes
  // with its work, always.
  bool draw_tracks = false;

  // True when every part is usable; otherwise says which and why.
  bool IsValid(std::string* error) const;
};

struct DecodedJunction {
  cv::Point2d position;  // sub-pixel, image pixels
  int p = 0;
  int q = 0;
  pattern::JunctionKind kind = pattern::JunctionKind::kDirect;
  bool interpolated = false;  // placed from relative junctions (thesis 5.1.4.6), not seen
};

// A junction seen but not labelled: no label could be proven for it (it is
// cut off from line 0, or its links disagree). Reported, never guessed.
struct UnlabelledJunction {
  cv::Point2d position;  // image pixels, where its segment's end meets its line
  pattern::JunctionKind kind = pattern::JunctionKind::kDirect;
};

struct DecodedLine {
  int p = 0;
  std::vector<cv::Point2d> points;  // sub-pixel centres, one per image row, ordered by y
};

struct StageTimes {
  double extraction_ms = 0;
  double interpretation_ms = 0;
  double subpixel_ms = 0;
  double total_ms = 0;
};

struct DecodeResult {
  bool ok = false;
  std::string error;  // why nothing could be labelled (ok == false)
  pattern::Side side = pattern::Side::kLeft;
  int width = 0;
  int height = 0;
  bool q_absolute = false;
  std::vector<DecodedJunction> junctions;      // ordered by p, then q
  std::vector<DecodedLine> lines;              // ordered by p
  std::vector<UnlabelledJunction> unlabelled;  // ordered by y
  StageTimes times;
  // Diagnostics.
  double pitch = 0.0;  // measured stripe pitch, px of the frame (0: none found)
  int binning = 1;     // n: extraction and interpretation ran on the frame binned n x n
  // The track chain's working frame: full-frame px per working px (above 1
  // reduced, below 1 enlarged; 1: the frame itself).
  double scale = 1.0;
  cv::Rect region;  // the part of the frame they ran on (DecodeParams::region_rise)
  // Sub-pixel centres measured ahead while the frame was interpreted
  // (DecodeParams::measure_ahead; 0: none). The output does not depend on it.
  int centres_measured_ahead = 0;
  int repairs = 0;
  int label_conflicts = 0;
  // Parts not joined to line 0, proven in themselves (the track chain), and
  // those of them the geometry placed (DecodeParams::geometry).
  int islands = 0;
  int islands_placed = 0;
  // Lines the geometry moved line 0's component by, where it clearly put it
  // elsewhere (0: it confirmed the labels, could not tell, or was not given).
  int line_zero_moved = 0;
  // The chain of line-0 candidates taken (TrackLabellingParams::
  // reference_choice): 0 the one nearest the centre row; more where the
  // geometry confirmed another (TrackChainParams::reference_tries).
  int reference_choice = 0;
  // Junctions whose labels the geometry ruled out (reported unlabelled).
  int ruled_out = 0;
  std::map<interpretation::LoopClass, int> loop_classes;
  // The repaired skeleton, CV_8UC1 0/255, frame size (redrawn when binned);
  // for the track chain, the ridge points of its line and segment tracks,
  // where DecodeParams::draw_tracks asks for them (else empty).
  cv::Mat skeleton;
};

// The default parameters with the skeleton chain.
DecodeParams SkeletonChainParams();

// The chain that decodes with `params` when a caller names `named` (nullopt:
// none): the one named; where none is, params.chain unless params ask for
// what only the skeleton chain does (the thesis's feature extraction, no
// repair), then the skeleton chain. nullopt, with the reason
// in `why`, when the track chain is named with such options.
std::optional<DecodeChain> ChainFor(std::optional<DecodeChain> named, const DecodeParams& params,
                                    std::string* why);

// Decodes a CV_8UC1 frame of the brick slide of `side`. A blank or saturated
// frame, or one whose reference line cannot be found, comes back with
// ok == false and a reason; nothing is guessed. Throws std::invalid_argument
// for an empty or non-CV_8UC1 frame or invalid params, and bsls::Cancelled
// when `cancel` asks to stop (asked between stages and inside the long ones).
DecodeResult Decode(const cv::Mat& grey, pattern::Side side, const DecodeParams& params = {},
                    const Cancellation& cancel = {});

}  // namespace bsls::decoder

#endif  // BSLS_DECODER_DECODER_H_
