#include "bsls/extraction/stripe_centre.h"

#include <Eigen/Dense>
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <numbers>
#include <opencv2/core/hal/intrin.hpp>
#include <stdexcept>
#include <vector>

#include "input_checks.h"

namespace bsls::extraction {
namespace {

using internal::RequireValid;

// Scratch space of n doubles, zeroed: on the stack up to kInline, else on
// the heap (the profiles of the default parameters fit on the stack).
class Scratch {
 public:
  explicit Scratch(size_t n) : n_(n) {
    if (n > kInline) heap_.resize(n);
    std::fill(data(), data() + n, 0.0);
  }
  double* data() { return n_ > kInline ? heap_.data() : local_.data(); }
  std::span<double> span() { return {data(), n_}; }

 private:
  static constexpr size_t kInline = 256;
  size_t n_;
  std::array<double, kInline> local_;
  std::vector<double> heap_;
};

double NormalCdf(double u) { return 0.5 * std::erfc(-u / std::numbers::sqrt2); }

// The 1 px pixel-integrated Gaussian of step 2: weights at offsets -5 .. 5
// (support ceil(4 sigma) + 1), computed once.
constexpr int kUnitSupport = 5;
const std::array<double, 2 * kUnitSupport + 1>& UnitKernel() {
  static const std::array<double, 2 * kUnitSupport + 1> kernel = [] {
    std::array<double, 2 * kUnitSupport + 1> k{};
    for (int i = -kUnitSupport; i <= kUnitSupport; ++i)
      k[static_cast<size_t>(i + kUnitSupport)] = NormalCdf(i + 0.5) - NormalCdf(i - 0.5);
    return k;
  }();
  return kernel;
}

// Values at the integer positions from .. to (inclusive, within 0 .. n-1) of
// the profile seen as pixels that are boxes of width 1 centred on their index,
// convolved with a Gaussian of 1 px, into out (n elements, zeroed); indices
// beyond the ends replicate the end samples. Each value is summed over the
// kernel in the same order; the interior runs kernel tap by tap over all
// positions (independent sums, no clamping).
void SmoothedAtPixels(std::span<const double> p, int from, int to, std::span<double> out) {
  const auto& kernel = UnitKernel();
  const int n = static_cast<int>(p.size());
  const int inner_from = std::max(from, kUnitSupport),
            inner_to = std::min(to, n - 1 - kUnitSupport);
  for (int k = -kUnitSupport; k <= kUnitSupport; ++k) {
    const double w = kernel[static_cast<size_t>(k + kUnitSupport)];
    const int count = inner_to - inner_from + 1;
    if (count <= 0) break;
    double* o = out.data() + inner_from;
    const double* q = p.data() + (inner_from - k);  // q[i] = p[inner_from + i - k]
    int i = 0;
#if CV_SIMD128_64F
    const cv::v_float64x2 vw = cv::v_setall_f64(w);
    for (; i + 2 <= count; i += 2) cv::v_store(o + i, cv::v_load(o + i) + cv::v_load(q + i) * vw);
#endif
    for (; i < count; ++i) o[i] += q[i] * w;
  }
  for (int i = from; i <= to; ++i) {
    if (i >= inner_from && i <= inner_to) continue;
    double sum = 0.0;
    for (int k = -kUnitSupport; k <= kUnitSupport; ++k)
      sum += p[static_cast<size_t>(std::clamp(i - k, 0, n - 1))] *
             kernel[static_cast<size_t>(k + kUnitSupport)];
    out[static_cast<size_t>(i)] = sum;
  }
}

// The first two derivatives, at any continuous position, of the profile seen
// as pixels that are boxes of width 1 centred on their index, convolved with
// a Gaussian of sigma. Indices beyond the ends replicate the end samples.
//
// Both come from the Gaussian and its derivative at the pixel edges,
// d^k/dx^k at x = sum_j p_j (G^(k-1)(x - j + 1/2) - G^(k-1)(x - j - 1/2)),
// so one evaluation takes 2 * support + 2 Gaussian values; for sigma >= 1/2
// they follow from two exp calls by the recurrence
// G(h - 1) = G(h) exp((2h - 1) / (2 sigma^2)).
class SmoothedDerivatives {
 public:
  SmoothedDerivatives(std::span<const double> p, double sigma)
      : p_(p),
        a_(0.5 / (sigma * sigma)),
        norm_(1.0 / (sigma * std::sqrt(2.0 * std::numbers::pi))),
        support_(static_cast<int>(std::ceil(4.0 * sigma)) + 1),
        recurrence_(sigma >= 0.5),
        ratio_step_(std::exp(-2.0 * a_)),
        g_(static_cast<size_t>(2 * support_ + 2)) {}

  // The profile indices that At(x, middle) reads: middle -+ Support() (clamped).
  int Support() const { return support_; }

  // First (d1) and second (d2) derivative at x; middle is std::lround(x).
  void At(double x, int middle, double* d1, double* d2) {
    const int n = static_cast<int>(p_.size());
    const int first = middle - support_;
    const int edges = 2 * support_ + 2;
    // g_[m] = G(h_m), h_m = x - first + 1/2 - m: the edge between pixels
    // first + m - 1 and first + m.
    const double h0 = (x - first) + 0.5;
    double* g = g_.data();
    if (recurrence_) {
      double gm = norm_ * std::exp(-a_ * h0 * h0);
      double ratio = std::exp(a_ * (2.0 * h0 - 1.0));
      for (int m = 0; m < edges; ++m) {
        g[m] = gm;
        gm *= ratio;
        ratio *= ratio_step_;
      }
    } else {
      for (int m = 0; m < edges; ++m) {
        const double h = h0 - m;
        g[m] = norm_ * std::exp(-a_ * h * h);
      }
    }
    // G'(h) = -h / sigma^2 G(h) = -2 a h G(h).
    double s1 = 0.0, s2 = 0.0;
    auto add = [&](int m, double pj) {
      const double g0 = g[m], g1 = g[m + 1];
      const double h = h0 - m;
      s1 += pj * (g0 - g1);
      s2 += pj * (h * g0 - (h - 1.0) * g1);
    };
    if (first >= 0 && first + 2 * support_ <= n - 1) {  // the usual case: no end replicated
      const double* p = p_.data() + first;
      for (int m = 0; m <= 2 * support_; ++m) add(m, p[m]);
    } else {
      for (int m = 0; m <= 2 * support_; ++m)
        add(m, p_[static_cast<size_t>(std::clamp(first + m, 0, n - 1))]);
    }
    *d1 = s1;
    *d2 = -2.0 * a_ * s2;
  }

 private:
  std::span<const double> p_;
  double a_;     // 1 / (2 sigma^2)
  double norm_;  // 1 / (sigma sqrt(2 pi))
  int support_;
  bool recurrence_;
  double ratio_step_;  // exp(-1 / sigma^2)
  Scratch g_;          // Gaussian at the pixel edges
};

// Positions lowest .. highest filled in on demand as one growing run:
// Cover(from, to, fill) calls fill(a, b) for each stretch a .. b of from ..
// to (clamped to the limits) not filled yet, and any gap between it and the
// run, so that every position is filled once and the run stays contiguous.
class CoveredRun {
 public:
  CoveredRun(int lowest, int highest) : lowest_(lowest), highest_(highest) {}

  template <typename Fill>
  void Cover(int from, int to, Fill fill) {
    from = std::max(from, lowest_);
    to = std::min(to, highest_);
    if (from > to) return;
    if (from_ > to_) {
      fill(from, to);
      from_ = from, to_ = to;
      return;
    }
    if (from < from_) fill(from, from_ - 1), from_ = from;
    if (to > to_) fill(to_ + 1, to), to_ = to;
  }

 private:
  int lowest_, highest_;
  int from_ = 0, to_ = -1;  // the run filled so far (empty)
};

// Binomial weights C(2r, k) / 4^r, k = 0 .. 2r (r <= 4).
std::array<double, 9> BinomialWeights(int radius) {
  std::array<double, 9> w{};
  w[0] = 1.0;
  for (size_t i = 0; i < static_cast<size_t>(2 * radius); ++i) {
    for (size_t k = i + 1; k >= 1; --k) w[k] = 0.5 * w[k] + 0.5 * w[k - 1];
    w[0] *= 0.5;
  }
  return w;
}

void RequireImage(const cv::Mat& image, const char* function) {
  if (image.empty()) throw std::invalid_argument(std::string(function) + ": image is empty");
  if (image.type() != CV_8UC1 && image.type() != CV_32FC1)
    throw std::invalid_argument(std::string(function) +
                                ": image must be CV_8UC1 or CV_32FC1, got " +
                                cv::typeToString(image.type()));
}

// RequireImage, and that `index` is one of the image's rows (row_major) or
// columns.
void RequireImageLine(const cv::Mat& image, int index, bool row_major, const char* function) {
  RequireImage(image, function);
  if (index < 0 || index >= (row_major ? image.rows : image.cols))
    throw std::invalid_argument(std::string(function) + (row_major ? ": row " : ": column ") +
                                std::to_string(index) + " outside the image");
}

// Half-length of the profile needed around the approximate position.
int ProfileReach(const StripeCentreParams& p) {
  const double max_sigma = std::max(p.min_sigma, p.sigma_per_width * p.max_width);
  return p.search_radius + static_cast<int>(std::ceil(0.5 * p.max_width)) + 6 +
         static_cast<int>(std::ceil(4.0 * max_sigma)) + 2;
}

// MeasureStripeProfile (stripe_centre.h) without the parameter check, on a
// profile whose elements may be filled in lazily: need(i0, i1) must make
// elements i0 .. i1 (within 0 .. n - 1) hold their values; it is called
// before any of them is read.
template <typename Need>
std::optional<StripeMeasurement> MeasureProfile(std::span<const double> profile, double approximate,
                                                const StripeCentreParams& params, Need need);

// A profile that is all there.
constexpr auto kWhole = [](int, int) {};

// The profile across the stripes of image row (row_major) or column `along`
// at positions lo .. hi of the other coordinate into `profile` (hi - lo + 1
// elements, zeroed): averaged over along_radius rows (columns) each side
// with binomial weights, renormalised where they run out at the border.
template <typename Pixel>
void ProfileAcross(const cv::Mat& image, bool row_major, int along, int lo, int hi,
                   const StripeCentreParams& params, std::span<double> profile) {
  const int along_size = row_major ? image.rows : image.cols;
  // The weights of each radius (0 .. 4, StripeCentreParams::IsValid), made once.
  static const std::array<std::array<double, 9>, 5> kWeights = [] {
    std::array<std::array<double, 9>, 5> w{};
    for (int r = 0; r < 5; ++r) w[static_cast<size_t>(r)] = BinomialWeights(r);
    return w;
  }();
  const std::array<double, 9>& weights = kWeights[static_cast<size_t>(params.along_radius)];
  const int first = std::max(0, along - params.along_radius);
  const int last = std::min(along_size - 1, along + params.along_radius);
  double total = 0.0;  // < 1 where the rows (columns) run out at the border
  for (int a = first; a <= last; ++a)
    total += weights[static_cast<size_t>(a - along + params.along_radius)];
  if (row_major) {
    for (int a = first; a <= last; ++a) {
      const double w = weights[static_cast<size_t>(a - along + params.along_radius)];
      const Pixel* row = image.ptr<Pixel>(a);
      for (int i = lo; i <= hi; ++i) profile[static_cast<size_t>(i - lo)] += w * row[i];
    }
  } else {
    for (int i = lo; i <= hi; ++i) {
      const Pixel* row = image.ptr<Pixel>(i);
      double& v = profile[static_cast<size_t>(i - lo)];
      for (int a = first; a <= last; ++a)
        v += weights[static_cast<size_t>(a - along + params.along_radius)] * row[a];
    }
  }
  if (total != 1.0)
    for (double& v : profile) v /= total;
}

// Measures across a stripe: `across` is the coordinate along the profile,
// `along` the fixed row (column) and `row_major` says which is the image row.
template <typename Pixel>
std::optional<double> MeasureAcross(const cv::Mat& image, bool row_major, int along,
                                    double approximate, const StripeCentreParams& params) {
  const int across_size = row_major ? image.cols : image.rows;
  if (!(approximate >= 0.0 && approximate <= across_size - 1)) return std::nullopt;
  const int reach = ProfileReach(params);
  const int centre = static_cast<int>(std::lround(approximate));
  const int lo = std::max(0, centre - reach);
  const int hi = std::min(across_size - 1, centre + reach);
  Scratch buffer(static_cast<size_t>(hi - lo + 1));
  const std::span<double> profile = buffer.span();
  // Only the part of the profile the measurement reads is taken from the
  // image (each element is the same on its own as in the whole profile): a
  // narrow stripe reads well under half of the reach that the widest needs.
  CoveredRun taken(0, hi - lo);
  auto need = [&](int from, int to) {
    taken.Cover(from, to, [&](int i0, int i1) {
      ProfileAcross<Pixel>(
          image, row_major, along, lo + i0, lo + i1, params,
          profile.subspan(static_cast<size_t>(i0), static_cast<size_t>(i1 - i0 + 1)));
    });
  };
  const auto m = MeasureProfile(std::span<const double>(profile), approximate - lo, params, need);
  if (!m) return std::nullopt;
  return m->centre + lo;
}

template <typename Need>
std::optional<StripeMeasurement> MeasureProfile(std::span<const double> profile, double approximate,
                                                const StripeCentreParams& params, Need need) {
  const int n = static_cast<int>(profile.size());
  if (n < 3 || !(approximate >= 0.0 && approximate <= n - 1)) return std::nullopt;

  // Peak of the 1 px smoothed profile inside the search range; the steps
  // below read it only within climb + reach of that range, and each only
  // where it has been smoothed (`smooth`).
  const int a = std::max(0, static_cast<int>(std::floor(approximate)) - params.search_radius);
  const int b = std::min(n - 1, static_cast<int>(std::ceil(approximate)) + params.search_radius);
  const int climb = static_cast<int>(std::ceil(0.5 * params.max_width));
  const int reach = climb + 6;
  const int first = std::max(0, a - climb - reach), last = std::min(n - 1, b + climb + reach);
  Scratch smoothed(profile.size());
  CoveredRun smoothed_run(first, last);
  auto smooth = [&](int from, int to) {
    smoothed_run.Cover(from, to, [&](int i0, int i1) {
      need(i0 - kUnitSupport, i1 + kUnitSupport);
      SmoothedAtPixels(profile, i0, i1, smoothed.span());
    });
  };
  const double* s = smoothed.data();
  auto at = [s](int i) { return s[i]; };
  // The search range, and the climb from it with the test of its top.
  smooth(a - climb - 1, b + climb + 1);
  int peak = a;
  for (int i = a; i <= b; ++i)
    if (at(i) > at(peak)) peak = i;
  // On a wide stripe the top may lie beyond the range: climb to it (the
  // centre itself must still come out within the range, checked below).
  for (int k = 0; k < climb && peak > 0 && at(peak - 1) > at(peak); ++k) --peak;
  for (int k = 0; k < climb && peak < n - 1 && at(peak + 1) > at(peak); ++k) ++peak;
  // The maximum must be a true local maximum, not the slope of something else.
  if (peak == 0 || peak == n - 1 || at(peak - 1) > at(peak) || at(peak + 1) > at(peak))
    return std::nullopt;

  // Grounds: lowest values before the profile rises again (a neighbour) or the reach ends.
  smooth(peak - reach, peak + reach);
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
  SmoothedDerivatives derivatives(profile, sigma);
  const double reach_from_peak = std::max(2.0, 0.5 * width + 1.0);  // flat tops
  double x = peak;
  double d1 = 0.0, d2 = 0.0;
  bool converged = false;
  auto derivatives_at = [&](double at_x) {
    const int middle = static_cast<int>(std::lround(at_x));
    need(middle - derivatives.Support(), middle + derivatives.Support());
    derivatives.At(at_x, middle, &d1, &d2);
  };
  for (int iteration = 0; iteration < 30; ++iteration) {
    derivatives_at(x);
    if (!(d2 < 0.0)) return std::nullopt;  // not a maximum
    const double step = std::clamp(d1 / d2, -0.5, 0.5);
    x -= step;
    if (std::abs(x - peak) > reach_from_peak) return std::nullopt;
    if (std::abs(step) < 1e-5) {
      converged = true;
      break;
    }
  }
  if (!converged) return std::nullopt;
  derivatives_at(x);
  if (!(d2 < 0.0)) return std::nullopt;
  if (std::abs(x - approximate) > params.search_radius + 0.5) return std::nullopt;
  return StripeMeasurement{x, width, contrast, sigma};
}

// The model FitCrowdedProfile fits to a profile v of n samples: a linear
// ground theta[0] + theta[1] (i - mid) and, per stripe j of k, a
// pixel-integrated Gaussian of area, centre and sigma theta[2 + 3 j],
// theta[3 + 3 j], theta[4 + 3 j] (profile indices).
class CrowdedModel {
 public:
  CrowdedModel(std::span<const double> v, int k, const StripeCentreParams& params)
      : v_(v),
        n_(static_cast<int>(v.size())),
        k_(k),
        m_(2 + 3 * k),
        mid_(0.5 * (n_ - 1)),
        ground_(*std::min_element(v.begin(), v.end())),
        highest_(*std::max_element(v.begin(), v.end())),
        max_sigma_(params.max_width / 2.3548),
        cdf_(static_cast<size_t>(n_ + 1)),
        pdf_(cdf_.size()),
        u_(cdf_.size()) {}

  int Parameters() const { return m_; }
  int Stripes() const { return k_; }

  // The starting point: a flat ground at the profile's lowest value, each
  // stripe min_sigma wide at its approximate position, as high as the
  // profile there stands above the ground (at least 1).
  Eigen::VectorXd Start(std::span<const double> approximate,
                        const StripeCentreParams& params) const {
    Eigen::VectorXd theta(m_);  // b0, b1, then (area, centre, sigma) per stripe
    theta[0] = ground_;
    theta[1] = 0.0;
    const double sigma0 = params.min_sigma;
    const double area_per_height = std::sqrt(2.0 * std::numbers::pi) * sigma0;
    for (int j = 0; j < k_; ++j) {
      const int at =
          std::clamp(static_cast<int>(std::lround(approximate[static_cast<size_t>(j)])), 0, n_ - 1);
      theta[2 + 3 * j] = std::max(1.0, v_[static_cast<size_t>(at)] - ground_) * area_per_height;
      theta[3 + 3 * j] = approximate[static_cast<size_t>(j)];
      theta[4 + 3 * j] = sigma0;
    }
    return theta;
  }

  // The residuals (model minus profile) at t into r, and their Jacobian
  // into jac unless it is null.
  void Residuals(const Eigen::VectorXd& t, Eigen::VectorXd* r, Eigen::MatrixXd* jac) {
    constexpr double kInvSqrt2Pi = 0.3989422804014327;
    const int n = n_, m = m_;
    r->resize(n);
    if (jac) jac->resize(n, m);
    for (int i = 0; i < n; ++i) (*r)[i] = t[0] + t[1] * (i - mid_) - v_[static_cast<size_t>(i)];
    if (jac) {
      for (int i = 0; i < n; ++i) {
        (*jac)(i, 0) = 1.0;
        (*jac)(i, 1) = i - mid_;
      }
    }
    // Per stripe, the normal CDF and density at the n + 1 pixel edges
    // (edge e between samples e - 1 and e), each shared by two samples.
    for (int j = 0; j < k_; ++j) {
      const double area = t[2 + 3 * j], c = t[3 + 3 * j], sg = t[4 + 3 * j];
      for (int e = 0; e <= n; ++e) {
        const size_t ei = static_cast<size_t>(e);
        u_[ei] = (e - 0.5 - c) / sg;
        cdf_[ei] = NormalCdf(u_[ei]);
        if (jac) pdf_[ei] = kInvSqrt2Pi * std::exp(-0.5 * u_[ei] * u_[ei]);
      }
      for (int i = 0; i < n; ++i) {
        const size_t lo = static_cast<size_t>(i), hi = lo + 1;
        const double g = cdf_[hi] - cdf_[lo];
        (*r)[i] += area * g;
        if (jac) {
          (*jac)(i, 2 + 3 * j) = g;
          (*jac)(i, 3 + 3 * j) = -area * (pdf_[hi] - pdf_[lo]) / sg;
          (*jac)(i, 4 + 3 * j) = -area * (u_[hi] * pdf_[hi] - u_[lo] * pdf_[lo]) / sg;
        }
      }
    }
  }

  // The search stays where an answer could be accepted (AcceptedCentres):
  // stripes no wider than max_width, none narrower than a quarter pixel,
  // centres on the profile, the ground within the profile's range at both
  // ends (a ground sinking below it while a wide stripe makes up the
  // difference is a plateau, not stripes).
  bool Feasible(const Eigen::VectorXd& t) const {
    for (const double end : {t[0] - t[1] * mid_, t[0] + t[1] * mid_})
      if (!(end >= ground_ - (highest_ - ground_) && end <= highest_)) return false;
    for (int j = 0; j < k_; ++j) {
      const double c = t[3 + 3 * j], sg = t[4 + 3 * j];
      if (!(t[2 + 3 * j] > 0.0 && sg > 0.25 && sg <= max_sigma_ && c > -0.5 && c < n_ - 0.5))
        return false;
    }
    return true;
  }

 private:
  std::span<const double> v_;
  int n_;
  int k_;
  int m_;
  double mid_;
  double ground_;   // the profile's lowest value
  double highest_;  // and its highest
  double max_sigma_;
  std::vector<double> cdf_, pdf_, u_;  // scratch of Residuals, per pixel edge
};

// Levenberg-Marquardt from *theta within the feasible region; true when it
// converged (a step that moves no centre or sigma by a thousandth of a
// pixel or barely lowers the cost, or no step that lowers it), with
// *theta and *cost (the squared residual norm) where it ended.
bool FitByLevenbergMarquardt(CrowdedModel& model, Eigen::VectorXd* theta_out, double* cost_out) {
  Eigen::VectorXd& theta = *theta_out;
  const int m = model.Parameters(), k = model.Stripes();
  Eigen::VectorXd r, r_new;
  Eigen::MatrixXd jac;

  model.Residuals(theta, &r, &jac);
  double cost = r.squaredNorm();
  double lambda = 1e-3;
  bool converged = false;
  for (int iteration = 0; iteration < 30 && !converged; ++iteration) {
    const Eigen::MatrixXd h = jac.transpose() * jac;
    const Eigen::VectorXd g = jac.transpose() * r;
    bool stepped = false;
    while (lambda < 1e12) {
      Eigen::MatrixXd damped = h;
      for (int d = 0; d < m; ++d) damped(d, d) += lambda * std::max(h(d, d), 1e-9);
      const Eigen::VectorXd delta = damped.ldlt().solve(-g);
      const Eigen::VectorXd candidate = theta + delta;
      if (delta.allFinite() && model.Feasible(candidate)) {
        model.Residuals(candidate, &r_new, nullptr);
        const double cost_new = r_new.squaredNorm();
        if (cost_new <= cost) {
          double largest_shift = 0.0;
          for (int j = 0; j < k; ++j)
            largest_shift =
                std::max({largest_shift, std::abs(delta[3 + 3 * j]), std::abs(delta[4 + 3 * j])});
          theta = candidate;
          // A thousandth of a pixel is far below what the noise allows.
          converged = largest_shift < 1e-3 || cost - cost_new <= 1e-6 * std::max(cost, 1.0);
          cost = cost_new;
          lambda = std::max(lambda * 0.1, 1e-9);
          stepped = true;
          break;
        }
      }
      lambda *= 10.0;
    }
    if (!stepped) {
      converged = true;  // no step lowers the cost: at the minimum (to rounding)
      break;
    }
    model.Residuals(theta, &r, &jac);
  }
  *cost_out = cost;
  return converged;
}

// The centres of a converged fit (theta, cost over n samples) that are
// kept. The fit as a whole: stripes of one projector seen side by side have
// like widths, none narrower than 0.4 min_sigma, and the model must
// explain the profile (residual RMS at most 7 % of the lowest stripe;
// noise sigma 3 leaves about 2 % of a 60 grey-level stripe). A fit that
// fails these has taken in something else: a segment, a shadow edge, or
// a stripe hidden behind another.
std::vector<std::optional<double>> AcceptedCentres(const Eigen::VectorXd& theta, double cost, int n,
                                                   std::span<const double> approximate,
                                                   const StripeCentreParams& params) {
  const int k = static_cast<int>(approximate.size());
  std::vector<std::optional<double>> out(static_cast<size_t>(k));
  std::vector<double> height(static_cast<size_t>(k));  // of each fitted stripe
  double narrowest = std::numeric_limits<double>::infinity(), widest = 0.0;
  for (int j = 0; j < k; ++j) {
    const double sg = theta[4 + 3 * j];
    height[static_cast<size_t>(j)] =
        theta[2 + 3 * j] * (NormalCdf(0.5 / sg) - NormalCdf(-0.5 / sg));
    narrowest = std::min(narrowest, sg);
    widest = std::max(widest, sg);
  }
  const double lowest = *std::min_element(height.begin(), height.end());
  if (!(std::sqrt(cost / n) <= 0.07 * lowest) || narrowest < 0.4 * params.min_sigma ||
      widest > 2.0 * narrowest)
    return out;
  // Each stripe (its FWHM is at most max_width: the search stayed feasible).
  for (int j = 0; j < k; ++j) {
    const double c = theta[3 + 3 * j];
    if (!(height[static_cast<size_t>(j)] >= params.min_contrast)) continue;
    if (std::abs(c - approximate[static_cast<size_t>(j)]) > params.search_radius + 0.5) continue;
    if (j > 0 && c - theta[3 + 3 * (j - 1)] <= 1.0) continue;
    if (j + 1 < k && theta[3 + 3 * (j + 1)] - c <= 1.0) continue;
    out[static_cast<size_t>(j)] = c;
  }
  return out;
}

// Thesis 5.1.4.8 (lines that crowd or overlap in the image), measured
// rather than skipped: the stripes near `approximate` (profile indices,
// ascending) as one pixel-integrated Gaussian each (area, centre, sigma) on
// a linear ground, fitted jointly by Levenberg-Marquardt, so that each
// one's light does not pull the others' centres. A stripe's centre is kept
// where its fitted height is at least min_contrast, its FWHM at most
// max_width, it lies within search_radius + 0.5 of its approximate position
// and more than 1 px from its neighbours in the fit.
std::vector<std::optional<double>> FitCrowdedProfile(std::span<const double> v,
                                                     std::span<const double> approximate,
                                                     const StripeCentreParams& params) {
  const int n = static_cast<int>(v.size());
  const int k = static_cast<int>(approximate.size());
  const int m = 2 + 3 * k;
  if (n < m + 2) return std::vector<std::optional<double>>(static_cast<size_t>(k));
  CrowdedModel model(v, k, params);
  Eigen::VectorXd theta = model.Start(approximate, params);
  double cost = 0.0;
  if (!FitByLevenbergMarquardt(model, &theta, &cost))
    return std::vector<std::optional<double>>(static_cast<size_t>(k));
  return AcceptedCentres(theta, cost, n, approximate, params);
}

template <typename Pixel>
std::vector<std::optional<double>> MeasureCrowdedRow(const cv::Mat& image, int y,
                                                     std::span<const double> approximate_x,
                                                     const StripeCentreParams& params) {
  const int margin = params.search_radius + 1;
  const int lo = std::max(0, static_cast<int>(std::floor(approximate_x.front())) - margin);
  const int hi =
      std::min(image.cols - 1, static_cast<int>(std::ceil(approximate_x.back())) + margin);
  Scratch buffer(static_cast<size_t>(hi - lo + 1));
  ProfileAcross<Pixel>(image, true, y, lo, hi, params, buffer.span());
  std::vector<double> local(approximate_x.begin(), approximate_x.end());
  for (double& x : local) x -= lo;
  std::vector<std::optional<double>> out = FitCrowdedProfile(buffer.span(), local, params);
  for (auto& c : out)
    if (c) *c += lo;
  return out;
}

}  // namespace

bool StripeCentreParams::IsValid(std::string* error) const {
  auto fail = [error](const char* why) {
    if (error) *error = why;
    return false;
  };
  if (search_radius < 1 || search_radius > 64) return fail("search_radius must lie in 1..64 px");
  if (!(max_width > 0.0 && max_width <= 256.0)) return fail("max_width must lie in (0, 256] px");
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
  return MeasureProfile(profile, approximate, params, kWhole);
}

std::optional<double> StripeCentreInRow(const cv::Mat& image, int y, double approximate_x,
                                        const StripeCentreParams& params) {
  RequireImageLine(image, y, true, "StripeCentreInRow");
  RequireValid(params, "StripeCentreInRow");
  return image.depth() == CV_8U
             ? MeasureAcross<unsigned char>(image, true, y, approximate_x, params)
             : MeasureAcross<float>(image, true, y, approximate_x, params);
}

std::optional<double> StripeCentreInColumn(const cv::Mat& image, int x, double approximate_y,
                                           const StripeCentreParams& params) {
  RequireImageLine(image, x, false, "StripeCentreInColumn");
  RequireValid(params, "StripeCentreInColumn");
  return image.depth() == CV_8U
             ? MeasureAcross<unsigned char>(image, false, x, approximate_y, params)
             : MeasureAcross<float>(image, false, x, approximate_y, params);
}

std::vector<std::optional<double>> StripeCentresInRow(const cv::Mat& image, int y,
                                                      std::span<const double> approximate_x,
                                                      const StripeCentreParams& params) {
  RequireImageLine(image, y, true, "StripeCentresInRow");
  RequireValid(params, "StripeCentresInRow");
  if (approximate_x.empty())
    throw std::invalid_argument("StripeCentresInRow: no approximate positions");
  if (!std::all_of(approximate_x.begin(), approximate_x.end(),
                   [](double x) { return std::isfinite(x); }))
    throw std::invalid_argument("StripeCentresInRow: approximate positions must be finite");
  if (!std::is_sorted(approximate_x.begin(), approximate_x.end()))
    throw std::invalid_argument("StripeCentresInRow: approximate positions not ascending");
  if (!(approximate_x.front() >= 0.0 && approximate_x.back() <= image.cols - 1))
    return std::vector<std::optional<double>>(approximate_x.size());
  return image.depth() == CV_8U ? MeasureCrowdedRow<unsigned char>(image, y, approximate_x, params)
                                : MeasureCrowdedRow<float>(image, y, approximate_x, params);
}

namespace {

// RidgeCentreInRow along any direction: pixel k of the profile (k = 0 ..
// 2 * reach) is first[k * along], its neighbours across the stripe
// first[k * along -+ across]. Returns the centre in profile units (0 = first).
template <int kPeak, int kReach>
std::optional<double> RidgeCentreAlong(const uchar* first, std::ptrdiff_t along,
                                       std::ptrdiff_t across) {
  constexpr int kSize = 2 * kReach + 1;
  int profile[kSize];
  for (int k = 0; k < kSize; ++k) {
    const uchar* p = first + k * along;
    profile[k] = p[-across] + 2 * p[0] + p[across];
  }
  int smooth[kSize] = {};
  for (int k = 2; k < kSize - 2; ++k)
    smooth[k] =
        profile[k - 2] + 4 * profile[k - 1] + 6 * profile[k] + 4 * profile[k + 1] + profile[k + 2];
  int peak = kReach;
  for (int k = kReach - kPeak; k <= kReach + kPeak; ++k)
    if (smooth[k] > smooth[peak]) peak = k;
  // Differences at peak - 1/2 and peak + 1/2: rising, then falling.
  const double rise = smooth[peak] - smooth[peak - 1], fall = smooth[peak + 1] - smooth[peak];
  if (rise < 0 || fall > 0 || rise == fall) return std::nullopt;
  return (peak - 0.5) + rise / (rise - fall);
}

// The smoothed profile is wanted at the guess +-2 px (where the peak is
// sought) and one pixel beyond; each smoothed value reads 2 px each side.
constexpr int kRidgePeak = 2, kRidgeReach = kRidgePeak + 3;
constexpr int kRidgeEdge = 9;  // px from the image's edges where nothing is measured

}  // namespace

std::optional<double> RidgeCentreInRow(const cv::Mat& image, int y, double approximate_x) {
  if (image.empty() || image.type() != CV_8UC1 || y < 1 || y >= image.rows - 1 ||
      !std::isfinite(approximate_x))
    return std::nullopt;
  const int x0 = static_cast<int>(std::lround(approximate_x));
  if (x0 - kRidgeEdge < 0 || x0 + kRidgeEdge >= image.cols) return std::nullopt;
  const auto c = RidgeCentreAlong<kRidgePeak, kRidgeReach>(
      image.ptr<uchar>(y) + x0 - kRidgeReach, 1, static_cast<std::ptrdiff_t>(image.step));
  if (!c) return std::nullopt;
  return x0 - kRidgeReach + *c;
}

std::optional<double> RidgeCentreInColumn(const cv::Mat& image, int x, double approximate_y) {
  if (image.empty() || image.type() != CV_8UC1 || x < 1 || x >= image.cols - 1 ||
      !std::isfinite(approximate_y))
    return std::nullopt;
  const int y0 = static_cast<int>(std::lround(approximate_y));
  if (y0 - kRidgeEdge < 0 || y0 + kRidgeEdge >= image.rows) return std::nullopt;
  const auto c = RidgeCentreAlong<kRidgePeak, kRidgeReach>(
      image.ptr<uchar>(y0 - kRidgeReach) + x, static_cast<std::ptrdiff_t>(image.step), 1);
  if (!c) return std::nullopt;
  return y0 - kRidgeReach + *c;
}

}  // namespace bsls::extraction
