#include "bsls/extraction/stripe_pitch.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include "input_checks.h"

namespace bsls::extraction {

bool StripePitchParams::IsValid(std::string* error) const {
  auto fail = [error](const char* why) {
    if (error) *error = why;
    return false;
  };
  if (!(central_band > 0.0 && central_band <= 1.0)) return fail("central_band must lie in (0, 1]");
  if (sampled_rows < 1) return fail("sampled_rows must be at least 1");
  if (!(min_pitch >= 2.0)) return fail("min_pitch must be at least 2 px");
  if (!(max_pitch_fraction > 0.0 && max_pitch_fraction <= 0.5))
    return fail("max_pitch_fraction must lie in (0, 0.5]");
  if (!(min_correlation > 0.0 && min_correlation < 1.0))
    return fail("min_correlation must lie in (0, 1)");
  if (!(min_significance >= 0.0)) return fail("min_significance must not be negative");
  if (!(harmonic_ratio > 0.0 && harmonic_ratio <= 1.0))
    return fail("harmonic_ratio must lie in (0, 1]");
  return true;
}

std::optional<double> MeasureStripePitch(const cv::Mat& grey, const StripePitchParams& params) {
  internal::RequireGrey8(grey, "MeasureStripePitch");
  internal::RequireValid(params, "MeasureStripePitch");
  const int width = grey.cols;
  const int max_lag = static_cast<int>(std::floor(params.max_pitch_fraction * width));
  if (width < 8 || max_lag + 2 >= width - 1 || max_lag < params.min_pitch) return std::nullopt;
  const int y0 = static_cast<int>(std::floor(0.5 * (1.0 - params.central_band) * grey.rows));
  const int y1 =
      std::max(y0 + 1, static_cast<int>(std::ceil(0.5 * (1.0 + params.central_band) * grey.rows)));
  const int rows = std::min(params.sampled_rows, y1 - y0);
  // Each sampled row's differences along x, zero-padded to twice its length
  // (a linear, not circular, correlation).
  const int n = cv::getOptimalDFTSize(2 * width);
  cv::Mat edges = cv::Mat::zeros(rows, n, CV_32F);
  for (int i = 0; i < rows; ++i) {
    const int y = y0 + static_cast<int>((i + 0.5) * (y1 - y0) / rows);
    const uchar* in = grey.ptr<uchar>(y);
    float* out = edges.ptr<float>(i);
    for (int x = 0; x + 1 < width; ++x) out[x] = static_cast<float>(in[x + 1]) - in[x];
  }
  // Summed power spectra, back to the summed autocorrelation.
  cv::Mat spectra, power, summed, correlation;
  cv::dft(edges, spectra, cv::DFT_ROWS);
  cv::mulSpectrums(spectra, spectra, power, cv::DFT_ROWS, /*conjB=*/true);
  cv::reduce(power, summed, 0, cv::REDUCE_SUM, CV_32F);
  cv::dft(summed, correlation, cv::DFT_INVERSE | cv::DFT_REAL_OUTPUT);
  const float* raw = correlation.ptr<float>(0);
  std::vector<double> c(static_cast<size_t>(max_lag + 2));
  for (int lag = 0; lag <= max_lag + 1; ++lag)
    c[lag] = raw[lag] / static_cast<double>(width - 1 - lag);
  if (!(c[0] > 0.0)) return std::nullopt;  // a flat band
  // The first zero crossing, then the highest lag beyond it.
  int first = 1;
  while (first <= max_lag && c[first] > 0.0) ++first;
  first = std::max(first, static_cast<int>(std::ceil(params.min_pitch)));
  int highest = -1;
  for (int lag = first; lag <= max_lag; ++lag)
    if (highest < 0 || c[lag] > c[highest]) highest = lag;
  // White noise alone correlates by about 1 / sqrt(pairs) of lag 0.
  const double pairs = static_cast<double>(rows) * (width - 1);
  const double least =
      c[0] * std::max(params.min_correlation, params.min_significance / std::sqrt(pairs));
  if (highest < 0 || c[highest] < least) return std::nullopt;
  // A comb whose pitch is not a whole number of pixels repeats exactly only
  // at a multiple of it, which may correlate a little higher: the first peak
  // that comes near the highest is the pitch.
  int best = highest;
  for (int lag = first; lag < highest; ++lag)
    if (c[lag] >= params.harmonic_ratio * c[highest] && c[lag] >= c[lag - 1] &&
        c[lag] >= c[lag + 1]) {
      best = lag;
      break;
    }
  const double below = c[best - 1], at = c[best], above = c[best + 1];
  const double curvature = below - 2.0 * at + above;
  const double offset =
      curvature < 0.0 ? std::clamp(0.5 * (below - above) / curvature, -0.5, 0.5) : 0.0;
  return best + offset;
}

}  // namespace bsls::extraction
