// Sub-pixel stripe centres on the grey image (beyond the thesis, whose
// skeleton stops at whole pixels, 4.3).
//
// Method (a Steger-style ridge detector, one-dimensional across the stripe):
//  1. The profile across the stripe is taken from the image, averaged along
//     the stripe over 2 * along_radius + 1 rows (columns) with binomial
//     weights (noise / ~1.6 for radius 1, negligible bias on gently curved
//     stripes).
//  2. Its peak is searched within search_radius of the approximate position
//     on the profile smoothed with a Gaussian of 1 px (and climbed to, if the
//     profile still rises at the end of the range); the grounds on both
//     sides are the lowest smoothed values before the profile rises again
//     (a neighbouring stripe) or max_width / 2 + 6 px; the contrast is the
//     peak above the higher ground; the width is the full width at half
//     contrast.
//  3. The centre is the zero of the first derivative of the profile smoothed
//     at sigma = max(min_sigma, sigma_per_width * width), capped so that the
//     kernel keeps clear of neighbouring stripes; it is found by Newton's
//     method on the continuous derivative of the pixel-integrated Gaussian
//     (pixels are treated as boxes, which removes the pixel-locking bias of
//     sampled kernels).
//  4. It is a proper ridge only if the peak is a local maximum, the
//     contrast is at least min_contrast, the width at most max_width, Newton
//     converges within max(2, width / 2 + 1) px of the peak and within
//     search_radius + 0.5 px of the approximate position, and the second
//     derivative there is negative; otherwise nullopt.
//
// Accuracy (tests/extraction/stripe_centre_test.cpp, synthetic stripes: box of
// width w blurred by a Gaussian PSF of 0.8 px, integrated over pixels, box
// contrast 60 grey levels, noise sigma 3, along_radius 1): RMS error
// about 0.08 px at w = 1 and 0.04-0.05 px for w = 2..10.
//
// Coordinates: x = column, y = row, origin at the centre of the top-left
// pixel (contracts section 5), so a stripe centred on pixel column 7 is at
// x = 7.0. Images: CV_8UC1 or CV_32FC1 grey, raw or smoothed.
//
// Errors: empty images, other types, a row / column outside the image and
// invalid parameters throw std::invalid_argument("<Function>: <reason>"); an
// approximate position outside the image simply gives nullopt.
//
// Thread-safety: pure functions of their arguments.
#ifndef BSLS_EXTRACTION_STRIPE_CENTRE_H_
#define BSLS_EXTRACTION_STRIPE_CENTRE_H_

#include <opencv2/core.hpp>
#include <optional>
#include <span>
#include <string>
#include <vector>

namespace bsls::extraction {

struct StripeCentreParams {
  int search_radius = 3;      // px; the peak must lie within this of the approximate position, >= 1
  double max_width = 14.0;    // px; a wider bright structure (FWHM) is not a stripe, > 0
  double min_contrast = 8.0;  // grey levels; peak above the higher ground, > 0
  int along_radius = 1;       // rows (columns) averaged along the stripe each side, 0..4
  double min_sigma = 1.0;     // px; smallest derivative scale, > 0
  double sigma_per_width = 0.4;  // derivative scale per px of FWHM, > 0
  double clearance = 2.5;        // sigma <= (distance to a neighbouring ground) / clearance, > 0

  // True when the values are usable; otherwise says why.
  bool IsValid(std::string* error) const;
};

// What MeasureStripeProfile finds on a one-dimensional profile.
struct StripeMeasurement {
  double centre = 0.0;    // sub-pixel position, profile index units
  double width = 0.0;     // full width at half contrast, px (of the 1 px smoothed profile)
  double contrast = 0.0;  // peak above the higher ground, profile units (grey levels)
  double sigma = 0.0;     // derivative scale used, px
};

// The stripe centre on a profile (element i is the pixel centred at i) near
// index `approximate`; nullopt when there is no proper ridge there.
std::optional<StripeMeasurement> MeasureStripeProfile(std::span<const double> profile,
                                                      double approximate,
                                                      const StripeCentreParams& params);

// Sub-pixel x of a (roughly vertical) stripe crossing row y near x = approximate_x.
std::optional<double> StripeCentreInRow(const cv::Mat& image, int y, double approximate_x,
                                        const StripeCentreParams& params = {});

// Sub-pixel y of a (roughly horizontal) stripe crossing column x near y = approximate_y.
std::optional<double> StripeCentreInColumn(const cv::Mat& image, int x, double approximate_y,
                                           const StripeCentreParams& params = {});

// Sub-pixel x of a (roughly vertical) stripe crossing row y within 2 px of
// x = approximate_x, by a cheaper measure than StripeCentreInRow for the
// track chain (docs/decoding.md, "The track chain"): rows y-1, y, y+1
// weighted 1-2-1, smoothed by a 5-tap binomial (sigma 1 px), and the zero of
// its first difference at the brightest smoothed pixel, interpolated
// linearly. Nullopt in the first and last row, within 9 px of the image's
// left or right edge, or where that pixel is no peak.
std::optional<double> RidgeCentreInRow(const cv::Mat& image, int y, double approximate_x);

// The same across a (roughly horizontal) stripe crossing column x near
// y = approximate_y (columns x-1, x, x+1 weighted 1-2-1).
std::optional<double> RidgeCentreInColumn(const cv::Mat& image, int x, double approximate_y);

// Sub-pixel x of (roughly vertical) stripes crossing row y close together,
// near approximate_x (ascending): one pixel-integrated Gaussian per stripe
// on a linear ground, fitted jointly (Levenberg-Marquardt) over the stripes
// and search_radius + 1 px beyond, so that each one's light does not pull
// the others' centres (thesis 5.1.4.8: lines that crowd in the image). An
// entry is nullopt where its stripe is no proper ridge in the fit (height
// below min_contrast, FWHM above max_width, beyond search_radius + 0.5 of
// its approximate position or within 1 px of a neighbour), all of them
// where the fit does not converge or a position lies outside the image.
// No positions, a position that is not finite or positions out of order
// throw std::invalid_argument.
std::vector<std::optional<double>> StripeCentresInRow(const cv::Mat& image, int y,
                                                      std::span<const double> approximate_x,
                                                      const StripeCentreParams& params = {});

}  // namespace bsls::extraction

#endif  // BSLS_EXTRACTION_STRIPE_CENTRE_H_
