// Private to bsls::decoder: the track chain's sub-pixel line centres
// (thesis 5.2): measured row by row along each labelled line track on the
// working frame, refilled beside its junctions, and cut where the track
// leaves its line.
#ifndef BSLS_DECODER_SRC_TRACK_CENTRES_H_
#define BSLS_DECODER_SRC_TRACK_CENTRES_H_

#include <opencv2/core.hpp>
#include <utility>
#include <vector>

#include "bsls/decoder/decoder.h"
#include "bsls/geometry/curve_fit.h"
#include "bsls/interpretation/ridge_tracks.h"
#include "bsls/interpretation/track_labelling.h"

namespace bsls::decoder::internal {

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
void MeasuredNear(const TrackCentres& c, int y, int reach, bool skip_own, geometry::Samples* s);

// The centres of line track `t`: measured in each row clear of the track's
// junctions, those far from their ridge points dropped, and the rows beside
// junctions refilled from the centres on both sides.
TrackCentres MeasureTrack(const cv::Mat& grey, const interpretation::TrackNetwork& net, int t,
                          const DecodeParams& params);

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
                       const interpretation::TrackLabels& labels, int t, TrackCentres* c);

// The measured centres of `line` within `reach` rows of row y0, as
// (row - y0, x) pairs.
std::vector<std::pair<double, double>> CentresNear(const TrackCentres& line, double y0, int reach);

}  // namespace bsls::decoder::internal

#endif  // BSLS_DECODER_SRC_TRACK_CENTRES_H_
