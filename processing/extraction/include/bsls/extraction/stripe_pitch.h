// The pitch of the vertical stripes in a frame, in pixels (not a thesis
// algorithm: the thesis's images are all 512 x 512 with a 12-15 px pitch, so
// it never needs it). The decoder uses it to choose the working resolution at
// which its pixel-sized parameters hold (docs/decoding.md, "Frame size").
//
// Method: sampled_rows rows evenly spaced over the central band of the frame
// are differentiated along x (so that shading, the lit area's outline and the
// dark ground do not count, only edges) and their autocorrelations summed
// (through the DFT, zero-padded, so not circular; each lag divided by the
// number of pixel pairs it has). The autocorrelation of the edges of a comb
// of stripes falls below zero within the stripe width, then peaks at the
// pitch; its multiples (2, 3 pitches) peak lower wherever the pitch varies
// across the frame, but a perfect comb of a pitch that is no whole number of
// pixels repeats exactly only at a multiple. The pitch is the first local
// peak beyond the first zero crossing, within [min_pitch,
// max_pitch_fraction * width], that reaches harmonic_ratio of the highest
// one there, refined by a parabola through the three lags around it. Segments
// (the rows' bright horizontal runs) have no edges along x and add nothing.
//
// Measured on the simulator's thesis scenes at 512 x 512 (the decoder's
// evaluation set, docs/decoding.md; synthetic combs in tests/extraction/
// stripe_pitch_test.cpp): plane 11.6 px, ball cap 10.4, face 15.2-15.4, ramp
// 20.8 (the true line spacings at the centre row: 10-14, 6-16, 13-42, 20-22);
// doubling the image size doubles the measurement to within 1 %. 16 rows
// measure these scenes to within 2 % of 64 rows (4 % on the 2048 face) at a
// quarter of the cost (0.08 ms at 512 x 512): enough for the binning, which
// rounds the pitch to a multiple of about 21 px.
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
  int sampled_rows = 16;             // rows taken from the band (fewer if it is shorter), >= 1
  double min_pitch = 4.0;            // px, smallest pitch reported, >= 2
  double max_pitch_fraction = 0.25;  // largest pitch reported, fraction of the width, (0, 0.5]
  // The pitch's autocorrelation must reach this fraction of the one at lag 0
  // (a comb of stripes: 0.05-0.6; white noise: about 0), (0, 1),
  double min_correlation = 0.01;
  // and this many times what white noise alone reaches (1 / sqrt(pixel
  // pairs) of lag 0), >= 0.
  double min_significance = 6.0;
  // The first local peak within this fraction of the highest is the pitch
  // (the others are its multiples), (0, 1].
  double harmonic_ratio = 0.8;

  // True when the values are usable; otherwise says why.
  bool IsValid(std::string* error) const;
};

// The dominant horizontal pitch (px) of the vertical stripes, or nullopt.
std::optional<double> MeasureStripePitch(const cv::Mat& grey, const StripePitchParams& params = {});

}  // namespace bsls::extraction

#endif  // BSLS_EXTRACTION_STRIPE_PITCH_H_
