#include "bsls/extraction/stripe_pitch.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>
#include <opencv2/core/utility.hpp>
#include <opencv2/imgproc.hpp>
#include <span>
#include <vector>

#include "input_checks.h"

namespace bsls::extraction {
namespace {

// Median of `v` (reordered); 0 for none.
double Median(std::vector<double>& v) {
  if (v.empty()) return 0.0;
  auto middle = v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2);
  std::nth_element(v.begin(), middle, v.end());
  return *middle;
}

// The row's pixel noise (sigma): the median absolute second difference,
// which the smooth profile of a stripe hardly touches, scaled for Gaussian
// noise (a second difference has sqrt(6) sigma). The differences are
// integers in [0, 1020], so the median is counted, not sorted.
double RowNoise(const uchar* row, int width) {
  std::array<int, 1021> counts{};
  for (int x = 1; x + 1 < width; ++x) ++counts[std::abs(row[x - 1] - 2 * row[x] + row[x + 1])];
  const int n = std::max(0, width - 2);
  int seen = 0, median = 0;
  while (median < 1020 && seen + counts[median] <= n / 2) seen += counts[median++];
  return 1.4826 * median / std::sqrt(6.0);
}

// The spread of a smoothed row's grey (95th - 5th percentile), counted in
// quarter grey levels (the smoothed values lie in [0, 255]).
double RowSpread(const float* r, int width) {
  constexpr int kBins = 1024;
  std::array<int, kBins> counts{};
  for (int x = 0; x < width; ++x)
    ++counts[std::clamp(static_cast<int>(r[x] * (kBins / 256.0f)), 0, kBins - 1)];
  auto percentile = [&](int rank) {
    int seen = 0, bin = 0;
    while (bin < kBins - 1 && seen + counts[bin] <= rank) seen += counts[bin++];
    return (bin + 0.5) * (256.0 / kBins);
  };
  return percentile(width * 95 / 100) - percentile(width * 5 / 100);
}

// The sub-pixel ridges of one smoothed row that stand out by `least`:
// local maxima (the first pixel of a flat top) whose prominence, looked for
// within `reach` px on either side, reaches it; each refined by a parabola.
void RowRidges(const float* r, int width, double least, int reach, std::vector<double>* ridges) {
  ridges->clear();
  for (int x = 1; x + 1 < width; ++x) {
    if (!(r[x] > r[x - 1])) continue;
    int end = x;  // the last pixel of a flat top
    while (end + 1 < width && r[end + 1] == r[x]) ++end;
    if (end + 1 >= width || !(r[end + 1] < r[x])) {
      x = end;
      continue;
    }
    // On each side, a point `least` below the top before a higher one (or
    // the reach): the walk ends at the first such point, since only whether
    // the prominence reaches `least` matters.
    const float floor = static_cast<float>(r[x] - least);
    bool deep_left = false, deep_right = false;
    for (int k = x - 1; k >= std::max(0, x - reach) && r[k] <= r[x]; --k)
      if (r[k] <= floor) {
        deep_left = true;
        break;
      }
    if (deep_left)
      for (int k = end + 1; k < std::min(width, end + 1 + reach) && r[k] <= r[x]; ++k)
        if (r[k] <= floor) {
          deep_right = true;
          break;
        }
    if (deep_left && deep_right) {
      double at = 0.5 * (x + end);
      if (end == x) {
        const double curvature = r[x - 1] - 2.0 * r[x] + r[x + 1];
        if (curvature < 0.0) at += std::clamp(0.5 * (r[x - 1] - r[x + 1]) / curvature, -0.5, 0.5);
      }
      ridges->push_back(at);
    }
    x = end;
  }
}

// The densest cluster of sorted `spacings` (members within `spread` of its
// smallest, relatively): its first and one-past-last index.
std::pair<size_t, size_t> DensestCluster(std::span<const double> spacings, double spread) {
  std::pair<size_t, size_t> best{0, 0};
  for (size_t i = 0, j = 0; i < spacings.size(); ++i) {
    j = std::max(j, i);
    while (j < spacings.size() && spacings[j] <= spacings[i] * (1.0 + spread)) ++j;
    if (j - i > best.second - best.first) best = {i, j};
  }
  return best;
}

}  // namespace

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
  if (!(smoothing_sigma >= 0.0 && smoothing_sigma <= 16.0))
    return fail("smoothing_sigma must lie in [0, 16] px");
  if (!(min_prominence_noise >= 0.0 && min_prominence_noise <= 1000.0))
    return fail("min_prominence_noise must lie in [0, 1000]");
  if (!(min_prominence_contrast >= 0.0 && min_prominence_contrast < 1.0))
    return fail("min_prominence_contrast must lie in [0, 1)");
  if (!(cluster_spread > 0.0 && cluster_spread < 1.0))
    return fail("cluster_spread must lie in (0, 1)");
  if (min_spacings < 1) return fail("min_spacings must be at least 1");
  if (!(min_share > 0.0 && min_share <= 1.0)) return fail("min_share must lie in (0, 1]");
  return true;
}

std::optional<double> MeasureStripePitch(const cv::Mat& grey, const StripePitchParams& params) {
  internal::RequireGrey8(grey, "MeasureStripePitch");
  internal::RequireValid(params, "MeasureStripePitch");
  const int width = grey.cols;
  const double max_pitch = std::floor(params.max_pitch_fraction * width);
  if (width < 8 || max_pitch < params.min_pitch) return std::nullopt;
  const int reach = static_cast<int>(max_pitch);
  const int y0 = static_cast<int>(std::floor(0.5 * (1.0 - params.central_band) * grey.rows));
  const int y1 =
      std::max(y0 + 1, static_cast<int>(std::ceil(0.5 * (1.0 + params.central_band) * grey.rows)));
  const int rows = std::min(params.sampled_rows, y1 - y0);

  // The smoothing leaves 1 / (2 sqrt(pi) sigma)^(1/2) of white noise's sigma.
  const double kept =
      params.smoothing_sigma > 0.5
          ? 1.0 / std::sqrt(2.0 * std::sqrt(std::numbers::pi) * params.smoothing_sigma)
          : 1.0;
  // The sampled rows, stacked and smoothed along x in one pass.
  cv::Mat sampled(rows, width, CV_8UC1);
  for (int i = 0; i < rows; ++i)
    grey.row(y0 + static_cast<int>((i + 0.5) * (y1 - y0) / rows)).copyTo(sampled.row(i));
  cv::Mat smoothed;
  if (params.smoothing_sigma > 0.0)
    cv::GaussianBlur(sampled, smoothed, cv::Size(0, 1), params.smoothing_sigma, 0.0,
                     cv::BORDER_REPLICATE);
  else
    smoothed = sampled;
  smoothed.convertTo(smoothed, CV_32F);
  // The rows are independent: in parallel, each row's spacings apart, then
  // gathered (they are sorted next, so their order does not matter).
  std::vector<std::vector<double>> spacings_of(rows);
  cv::parallel_for_(cv::Range(0, rows), [&](const cv::Range& range) {
    std::vector<double> ridges;
    for (int i = range.start; i < range.end; ++i) {
      const float* r = smoothed.ptr<float>(i);
      const double noise = RowNoise(sampled.ptr<uchar>(i), width) * kept;
      const double least = std::max({params.min_prominence_noise * noise,
                                     params.min_prominence_contrast * RowSpread(r, width), 1e-3});
      RowRidges(r, width, least, reach, &ridges);
      for (size_t k = 1; k < ridges.size(); ++k) {
        const double s = ridges[k] - ridges[k - 1];
        if (s >= params.min_pitch && s <= max_pitch) spacings_of[i].push_back(s);
      }
    }
  });
  std::vector<double> spacings;
  for (const std::vector<double>& row : spacings_of)
    spacings.insert(spacings.end(), row.begin(), row.end());
  if (spacings.empty()) return std::nullopt;
  std::sort(spacings.begin(), spacings.end());
  auto [first, last] = DensestCluster(spacings, params.cluster_spread);
  // A cluster at half the spacing with at least half the count is the pitch.
  std::vector<double> cluster(spacings.begin() + first, spacings.begin() + last);
  const double half = 0.5 * Median(cluster);
  {
    const auto lo =
        std::lower_bound(spacings.begin(), spacings.end(), half / (1.0 + params.cluster_spread));
    const auto hi =
        std::upper_bound(spacings.begin(), spacings.end(), half * (1.0 + params.cluster_spread));
    if (lo != hi) {
      const auto [b0, b1] = DensestCluster(std::span<const double>(lo, hi), params.cluster_spread);
      if (2 * (b1 - b0) >= last - first) {
        first = static_cast<size_t>(lo - spacings.begin()) + b0;
        last = static_cast<size_t>(lo - spacings.begin()) + b1;
      }
    }
  }
  const size_t count = last - first;
  if (static_cast<int>(count) < params.min_spacings ||
      static_cast<double>(count) < params.min_share * spacings.size())
    return std::nullopt;
  cluster.assign(spacings.begin() + first, spacings.begin() + last);
  return Median(cluster);
}

}  // namespace bsls::extraction
