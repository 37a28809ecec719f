#include "bsls/extraction/stripe_centre.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>
#include <vector>

#include "input_checks.h"

namespace bsls::extraction {
namespace {

using internal::RequireValid;

double NormalCdf(double u) { return 0.5 * std::erfc(-u / std::numbers::sqrt2); }

double Gauss(double u, double sigma) {
  const double t = u / sigma;
  return std::exp(-0.5 * t * t) / (sigma * std::sqrt(2.0 * std::numbers::pi));
}

double GaussDerivative(double u, double sigma) { return -u / (sigma * sigma) * Gauss(u, sigma); }

// The profile seen as pixels that are boxes of width 1 centred on their
// index, convolved with a Gaussian of sigma: value and first two
// derivatives at any continuous position. Indices beyond the ends replicate
// the end samples.
class SmoothedProfile {
 public:
  SmoothedProfile(std::span<const double> p, double sigma) : p_(p), sigma_(sigma) {
    support_ = static_cast<int>(std::ceil(4.0 * sigma)) + 1;
  }

  // Values at the integer positions 0 .. n-1 (one kernel for all).
  std::vector<double> ValuesAtPixels() const {
    std::vector<double> kernel(static_cast<size_t>(2 * support_ + 1));
    for (int k = -support_; k <= support_; ++k)
      kernel[static_cast<size_t>(k + support_)] =
          NormalCdf((k + 0.5) / sigma_) - NormalCdf((k - 0.5) / sigma_);
    const int n = static_cast<int>(p_.size());
    std::vector<double> out(p_.size(), 0.0);
    for (int i = 0; i < n; ++i) {
      double sum = 0.0;
      for (int k = -support_; k <= support_; ++k)
        sum += p_[static_cast<size_t>(std::clamp(i - k, 0, n - 1))] *
               kernel[static_cast<size_t>(k + support_)];
      out[static_cast<size_t>(i)] = sum;
    }
    return out;
  }
  double D1(double x) const {
    return Sum(x, [this](double u) { return Gauss(u + 0.5, sigma_) - Gauss(u - 0.5, sigma_); });
  }
  double D2(double x) const {
    return Sum(x, [this](double u) {
      return GaussDerivative(u + 0.5, sigma_) - GaussDerivative(u - 0.5, sigma_);
    });
  }

 private:
  template <typename Weight>
  double Sum(double x, Weight weight) const {
    const int n = static_cast<int>(p_.size());
    const int centre = static_cast<int>(std::lround(x));
    double sum = 0.0;
    for (int j = centre - support_; j <= centre + support_; ++j)
      sum += p_[static_cast<size_t>(std::clamp(j, 0, n - 1))] * weight(x - j);
    return sum;
  }

  std::span<const double> p_;
  double sigma_;
  int support_;
};

// Binomial weights C(2r, k) / 4^r, k = 0 .. 2r.
std::vector<double> BinomialWeights(int radius) {
  std::vector<double> w{1.0};
  for (int i = 0; i < 2 * radius; ++i) {
    std::vector<double> next(w.size() + 1, 0.0);
    for (size_t k = 0; k < w.size(); ++k) {
      next[k] += 0.5 * w[k];
      next[k + 1] += 0.5 * w[k];
    }
    w = std::move(next);
  }
  return w;
}

double PixelAt(const cv::Mat& image, int y, int x) {
  return image.depth() == CV_8U ? image.at<unsigned char>(y, x) : image.at<float>(y, x);
}

void RequireImage(const cv::Mat& image, const char* function) {
  if (image.empty()) throw std::invalid_argument(std::string(function) + ": image is empty");
  if (image.type() != CV_8UC1 && image.type() != CV_32FC1)
    throw std::invalid_argument(std::string(function) +
                                ": image must be CV_8UC1 or CV_32FC1, got " +
                                cv::typeToString(image.type()));
}

// Half-length of the profile needed around the approximate position.
int ProfileReach(const StripeCentreParams& p) {
  const double max_sigma = std::max(p.min_sigma, p.sigma_per_width * p.max_width);
  return p.search_radius + static_cast<int>(std::ceil(0.5 * p.max_width)) + 6 +
         static_cast<int>(std::ceil(4.0 * max_sigma)) + 2;
}

// Measures across a stripe: `across` is the coordinate along the profile,
// `along` the fixed row (column); at(along, across) reads the image.
template <typename At>
std::optional<double> MeasureAcross(int along, int along_size, int across_size, double approximate,
                                    const StripeCentreParams& params, At at) {
  if (!(approximate >= 0.0 && approximate <= across_size - 1)) return std::nullopt;
  const int reach = ProfileReach(params);
  const int centre = static_cast<int>(std::lround(approximate));
  const int lo = std::max(0, centre - reach);
  const int hi = std::min(across_size - 1, centre + reach);
  const std::vector<double> weights = BinomialWeights(params.along_radius);
  std::vector<double> profile(static_cast<size_t>(hi - lo + 1), 0.0);
  double total = 0.0;
  for (int k = -params.along_radius; k <= params.along_radius; ++k) {
    const int a = along + k;
    if (a < 0 || a >= along_size) continue;  // renormalised below
    const double w = weights[static_cast<size_t>(k + params.along_radius)];
    total += w;
    for (int i = lo; i <= hi; ++i) profile[static_cast<size_t>(i - lo)] += w * at(a, i);
  }
  for (double& v : profile) v /= total;
  const auto m = MeasureStripeProfile(profile, approximate - lo, params);
  if (!m) return std::nullopt;
  return m->centre + lo;
}

}  // namespace

bool StripeCentreParams::IsValid(std::string* error) const {
  auto fail = [error](const char* why) {
    if (error) *error = why;
    return false;
  };
  if (search_radius < 1 || search_radius > 64) return fail("search_radius must lie in 1..64 px");
  if (!(max_width > 0.0 && max_width <= 64.0)) return fail("max_width must lie in (0, 64] px");
  if (!(min_contrast > 0.0)) return fail("min_contrast must be > 0 grey levels");
  if (along_radius < 0 || along_radius > 4) return fail("along_radius must lie in 0..4");
  if (!(min_sigma > 0.0 && min_sigma <= 16.0)) return fail("min_sigma must lie in (0, 16] px");
  if (!(sigma_per_width > 0.0 && sigma_per_width <= 2.0))
    return fail("sigma_per_width must lie in (0, 2]");
  if (!(clearance > 0.0)) return fail("clearance must be > 0");
  return true;
}

std::optional<StripeMeasurement> MeasureStripeProfile(std::span<const double> profile,
                                                      double approximate,
                                                      const StripeCentreParams& params) {
  RequireValid(params, "MeasureStripeProfile");
  const int n = static_cast<int>(profile.size());
  if (n < 3 || !(approximate >= 0.0 && approximate <= n - 1)) return std::nullopt;

  // Peak of the 1 px smoothed profile inside the search range.
  const std::vector<double> s = SmoothedProfile(profile, 1.0).ValuesAtPixels();
  auto at = [&s](int i) { return s[static_cast<size_t>(i)]; };
  const int a = std::max(0, static_cast<int>(std::floor(approximate)) - params.search_radius);
  const int b = std::min(n - 1, static_cast<int>(std::ceil(approximate)) + params.search_radius);
  int peak = a;
  for (int i = a; i <= b; ++i)
    if (at(i) > at(peak)) peak = i;
  // On a wide stripe the top may lie beyond the range: climb to it (the
  // centre itself must still come out within the range, checked below).
  const int climb = static_cast<int>(std::ceil(0.5 * params.max_width));
  for (int k = 0; k < climb && peak > 0 && at(peak - 1) > at(peak); ++k) --peak;
  for (int k = 0; k < climb && peak < n - 1 && at(peak + 1) > at(peak); ++k) ++peak;
  // The maximum must be a true local maximum, not the slope of something else.
  if (peak == 0 || peak == n - 1 || at(peak - 1) > at(peak) || at(peak + 1) > at(peak))
    return std::nullopt;

  // Grounds: lowest values before the profile rises again (a neighbour) or the reach ends.
  const int reach = static_cast<int>(std::ceil(0.5 * params.max_width)) + 6;
  auto ground = [&](int step, int* where) {
    double deepest = at(peak);  // lowest value within the reach
    for (int k = 1; k <= reach; ++k) {
      const int i = peak + step * k;
      if (i < 0 || i >= n) break;
      deepest = std::min(deepest, at(i));
    }
    // Walk out; a rise ends the walk only after a real descent (half-way
    // down to the deepest value), so noise dips on a flat top do not.
    double low = at(peak);
    *where = peak;
    for (int k = 1; k <= reach; ++k) {
      const int i = peak + step * k;
      if (i < 0 || i >= n) break;
      if (at(i) < low) {
        low = at(i);
        *where = i;
      } else if (at(i) > low + 1.0 + 0.1 * (at(peak) - low) &&
                 low <= at(peak) - 0.5 * (at(peak) - deepest)) {
        break;
      }
    }
    return low;
  };
  int left_at = peak, right_at = peak;
  const double left = ground(-1, &left_at);
  const double right = ground(+1, &right_at);
  const double contrast = at(peak) - std::max(left, right);
  if (!(contrast >= params.min_contrast)) return std::nullopt;

  // Full width at half contrast, by linear interpolation.
  const double half = at(peak) - 0.5 * (at(peak) - 0.5 * (left + right));
  auto crossing = [&](int step, int end) {
    for (int i = peak; i != end; i += step) {
      const double v0 = at(i), v1 = at(i + step);
      if (v1 <= half) return i + step * (v0 - half) / (v0 - v1);
    }
    return static_cast<double>(end);
  };
  const double width = crossing(+1, right_at) - crossing(-1, left_at);
  if (!(width <= params.max_width)) return std::nullopt;

  // Derivative scale matched to the width, clear of the neighbours.
  double sigma = std::max(params.min_sigma, params.sigma_per_width * width);
  const int clear = std::min(peak - left_at, right_at - peak);
  sigma = std::min(sigma, std::max(params.min_sigma, clear / params.clearance));

  // Newton's method on the first derivative of the smoothed profile.
  const SmoothedProfile smooth(profile, sigma);
  const double reach_from_peak = std::max(2.0, 0.5 * width + 1.0);  // flat tops
  double x = peak;
  bool converged = false;
  for (int iteration = 0; iteration < 30; ++iteration) {
    const double d2 = smooth.D2(x);
    if (!(d2 < 0.0)) return std::nullopt;  // not a maximum
    const double step = std::clamp(smooth.D1(x) / d2, -0.5, 0.5);
    x -= step;
    if (std::abs(x - peak) > reach_from_peak) return std::nullopt;
    if (std::abs(step) < 1e-5) {
      converged = true;
      break;
    }
  }
  if (!converged || !(smooth.D2(x) < 0.0)) return std::nullopt;
  if (std::abs(x - approximate) > params.search_radius + 0.5) return std::nullopt;
  return StripeMeasurement{x, width, contrast, sigma};
}

std::optional<double> StripeCentreInRow(const cv::Mat& image, int y, double approximate_x,
                                        const StripeCentreParams& params) {
  RequireImage(image, "StripeCentreInRow");
  RequireValid(params, "StripeCentreInRow");
  if (y < 0 || y >= image.rows)
    throw std::invalid_argument("StripeCentreInRow: row " + std::to_string(y) +
                                " outside the image");
  return MeasureAcross(y, image.rows, image.cols, approximate_x, params,
                       [&image](int row, int col) { return PixelAt(image, row, col); });
}

std::optional<double> StripeCentreInColumn(const cv::Mat& image, int x, double approximate_y,
                                           const StripeCentreParams& params) {
  RequireImage(image, "StripeCentreInColumn");
  RequireValid(params, "StripeCentreInColumn");
  if (x < 0 || x >= image.cols)
    throw std::invalid_argument("StripeCentreInColumn: column " + std::to_string(x) +
                                " outside the image");
  return MeasureAcross(x, image.cols, image.rows, approximate_y, params,
                       [&image](int col, int row) { return PixelAt(image, row, col); });
}

}  // namespace bsls::extraction
