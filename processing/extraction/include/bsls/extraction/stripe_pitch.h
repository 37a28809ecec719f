// The pitch of the vertical stripes in a frame, in pixels (not a thesis
// algorithm: the thesis's images are all 512 x 512 with a 12-15 px pitch, so
// it never needs it). The decoder uses it to choose the working resolution at
// which its pixel-sized parameters hold (docs/decoding.md, "Frame size").
//
// Method: the stripes' ridges along sampled_rows rows evenly spaced over
// the central band of the frame. Each row is smoothed (smoothing_sigma) and
// its local maxima kept where they stand out: a peak's prominence (its
// height above the higher of the lowest points between it and a higher peak
// on either side, looked for within the largest pitch) must reach
// min_prominence_noise times the row's pixel noise (from the median absolute
// second difference, which a stripe's smooth profile hardly touches) and
// min_prominence_contrast of the row's spread of grey (95th - 5th
// percentile). Each kept peak is refined by a parabola; the spacings of
// neighbouring peaks are pooled over the rows. The pitch is the median of
// the densest cluster of spacings (those within cluster_spread of one
// another); a cluster at half that spacing with at least half its count is
// taken instead (a stripe missing in every other place doubles a spacing,
// nothing halves one). Segments (the rows' bright horizontal runs) make no
// peaks of their own; an occluding edge or a shadow only removes spacings.
//
// Why not the autocorrelation of the rows (the measurement before): where
// the pitch changes across the frame (perspective, a face's side, an object
// in front of the base plane), the autocorrelation's first peak smears out
// and a multiple wins: 2x on the outside corpus's face/right, which was then
// binned 2 x 2 and lost a fifth of its junctions, and 3.6x on a held-out
// face of 8.7 px (tuning seed 44). Neighbouring ridges are the pitch by
// definition, wherever they are.
//
// Cost: linear in the sampled pixels (each peak's walk is bounded by the
// largest pitch).
//
// Images: CV_8UC1 grey, x = column, y = row.
//
// Errors: an empty or non-CV_8UC1 image and invalid parameters throw
// std::invalid_argument("MeasureStripePitch: <reason>"); a frame without a
// periodic stripe pattern (blank, one stripe, noise) gives nullopt.
//
// Thread-safety: pure function of its arguments.
#ifndef BSLS_EXTRACTION_STRIPE_PITCH_H_
#define BSLS_EXTRACTION_STRIPE_PITCH_H_

#include <opencv2/core.hpp>
#include <optional>
#include <string>

namespace bsls::extraction {

struct StripePitchParams {
  double central_band = 0.6;         // fraction of the rows, centred, that are sampled, (0, 1]
  int sampled_rows = 32;             // rows taken from the band (fewer if it is shorter), >= 1
  double min_pitch = 4.0;            // px, smallest pitch reported, >= 2
  double max_pitch_fraction = 0.25;  // largest pitch reported, fraction of the width, (0, 0.5]
  double smoothing_sigma = 1.0;      // px, Gaussian along the row, >= 0
  // A ridge's prominence must reach this many times the row's pixel noise
  // (sigma, after the smoothing), >= 0,
  double min_prominence_noise = 6.0;
  // and this fraction of the row's spread of grey, [0, 1).
  double min_prominence_contrast = 0.1;
  // Spacings within this fraction of one another form one cluster, (0, 1).
  double cluster_spread = 0.15;
  // At least this many spacings in the chosen cluster, >= 1,
  int min_spacings = 12;
  // and at least this share of all the spacings, (0, 1].
  double min_share = 0.05;

  // True when the values are usable; otherwise says why.
  bool IsValid(std::string* error) const;
};

// The dominant horizontal pitch (px) of the vertical stripes, or nullopt.
std::optional<double> MeasureStripePitch(const cv::Mat& grey, const StripePitchParams& params = {});

}  // namespace bsls::extraction

#endif  // BSLS_EXTRACTION_STRIPE_PITCH_H_
