#include "bsls/extraction/stripe_detect.h"

#include <algorithm>
#include <cmath>
#include <opencv2/core/hal/intrin.hpp>
#include <opencv2/imgproc.hpp>
#include <vector>

#include "bands.h"
#include "hysteresis.h"
#include "input_checks.h"

namespace bsls::extraction {
namespace {

using internal::RequireGrey8;
using internal::RequireValid;

// 2 * t * phi(t) at t = 1: the scale-normalised curvature of a unit bar at its
// best scale; dividing by it makes the ridge strength read in grey levels.
constexpr float kBarResponse = 2.0f * 0.24197072f;

// The kernel half-width of the Gaussian smoothing used throughout.
int BlurHalf(double sigma) { return std::max(1, static_cast<int>(std::ceil(3.0 * sigma))); }

cv::Mat Blur(const cv::Mat& values, double sigma) {
  cv::Mat out;
  internal::GaussianInto(values, sigma, BlurHalf(sigma), &out);
  return out;
}

std::vector<double> Scales(const StripeDetectParams& p) {
  std::vector<double> scales;
  if (p.scale_count == 1) return {p.min_scale};
  const double ratio = std::pow(p.max_scale / p.min_scale, 1.0 / (p.scale_count - 1));
  for (int i = 0; i < p.scale_count; ++i) scales.push_back(p.min_scale * std::pow(ratio, i));
  return scales;
}

// One row of out = max(out, sigma^2 * max(0, -lambda_min(Hessian(L))) / kBarResponse)
// (scale = sigma^2 / kBarResponse), the Hessian taken by central differences
// of the smoothed image L from its rows above (up), at (mid) and below
// (down), columns replicated at the ends.
void AccumulateRidgeRow(const float* up, const float* mid, const float* down, int cols, float scale,
                        float* out) {
  auto at = [&](int x, int xl, int xr) {
    const float lxx = mid[xr] - 2.0f * mid[x] + mid[xl];
    const float lyy = down[x] - 2.0f * mid[x] + up[x];
    const float lxy = 0.25f * (down[xr] - down[xl] - up[xr] + up[xl]);
    const float half_trace = 0.5f * (lxx + lyy);
    const float half_diff = 0.5f * (lxx - lyy);
    const float lambda_min = half_trace - std::sqrt(half_diff * half_diff + lxy * lxy);
    out[x] = std::max(out[x], -lambda_min * scale);
  };
  if (cols == 1) {
    at(0, 0, 0);
    return;
  }
  at(0, 0, 1);
  int x = 1;
#if CV_SIMD128
  // The same operations in the same order, four columns at a time.
  const cv::v_float32x4 two = cv::v_setall_f32(2.0f), quarter = cv::v_setall_f32(0.25f),
                        half = cv::v_setall_f32(0.5f), minus_scale = cv::v_setall_f32(-scale);
  for (; x + 4 < cols; x += 4) {
    const cv::v_float32x4 m = cv::v_load(mid + x);
    const cv::v_float32x4 lxx = cv::v_load(mid + x + 1) - two * m + cv::v_load(mid + x - 1);
    const cv::v_float32x4 lyy = cv::v_load(down + x) - two * m + cv::v_load(up + x);
    const cv::v_float32x4 lxy = quarter * (cv::v_load(down + x + 1) - cv::v_load(down + x - 1) -
                                           cv::v_load(up + x + 1) + cv::v_load(up + x - 1));
    const cv::v_float32x4 half_trace = half * (lxx + lyy);
    const cv::v_float32x4 half_diff = half * (lxx - lyy);
    const cv::v_float32x4 lambda_min = half_trace - cv::v_sqrt(half_diff * half_diff + lxy * lxy);
    // v_max(a, b) keeps b where they compare equal (+0 / -0), as std::max(b, a).
    cv::v_store(out + x, cv::v_max(lambda_min * minus_scale, cv::v_load(out + x)));
  }
#endif
  for (; x + 1 < cols; ++x) at(x, x - 1, x + 1);  // interior: no clamping
  at(cols - 1, cols - 2, cols - 1);
}

// Rows y0 .. y1 - 1 of the multi-scale ridge strength of the image
// (CV_8UC1; into the same rows of *strength, CV_32FC1 of the image's size).
void RidgeStrengthRows(const cv::Mat& grey, const std::vector<double>& scales, int y0, int y1,
                       cv::Mat* strength) {
  const int rows = grey.rows;
  const int a = std::max(0, y0 - 1), b = std::min(rows, y1 + 1);  // rows of L needed
  strength->rowRange(y0, y1).setTo(0.0f);
  cv::Mat smoothed;
  for (double sigma : scales) {
    internal::GaussianInto(grey.rowRange(a, b), sigma, BlurHalf(sigma), &smoothed);
    const float scale = static_cast<float>(sigma * sigma) / kBarResponse;
    for (int y = y0; y < y1; ++y)
      AccumulateRidgeRow(smoothed.ptr<float>(std::max(y - 1, 0) - a), smoothed.ptr<float>(y - a),
                         smoothed.ptr<float>(std::min(y + 1, rows - 1) - a), grey.cols, scale,
                         strength->ptr<float>(y));
  }
}

// Multi-scale ridge strength, band by band in parallel.
cv::Mat ComputeRidgeStrength(const cv::Mat& grey, const StripeDetectParams& p) {
  cv::Mat strength(grey.size(), CV_32F);
  const std::vector<double> scales = Scales(p);
  internal::ForEachBand(
      grey.rows, [&](int y0, int y1) { RidgeStrengthRows(grey, scales, y0, y1, &strength); });
  return strength;
}

// Immerkaer's noise estimate made robust: the median absolute response to
// [1 -2 1; -2 4 -2; 1 -2 1] (which cancels smooth shading), scaled to the
// standard deviation of white noise, over pixels whose 3 x 3 neighbourhood is
// not clipped at 0 or 255 (every other row and column: plenty for a median).
// Stripes inflate it a little. These are the samples of rows y0 .. y1 - 1
// (all integers, so exact in float).
void NoiseSamples(const cv::Mat& grey, int y0, int y1, std::vector<float>* values) {
  for (int y = std::max(1, y0 | 1); y < y1 && y + 1 < grey.rows; y += 2) {
    const unsigned char* u = grey.ptr<unsigned char>(y - 1);
    const unsigned char* m = grey.ptr<unsigned char>(y);
    const unsigned char* d = grey.ptr<unsigned char>(y + 1);
    for (int x = 1; x + 1 < grey.cols; x += 2) {
      const int lo = std::min(
          std::min(std::min(u[x - 1], u[x]), std::min(u[x + 1], m[x - 1])),
          std::min(std::min(m[x], m[x + 1]), std::min(std::min(d[x - 1], d[x]), d[x + 1])));
      const int hi = std::max(
          std::max(std::max(u[x - 1], u[x]), std::max(u[x + 1], m[x - 1])),
          std::max(std::max(m[x], m[x + 1]), std::max(std::max(d[x - 1], d[x]), d[x + 1])));
      if (lo == 0 || hi == 255) continue;
      const int response = u[x - 1] + u[x + 1] + d[x - 1] + d[x + 1] -
                           2 * (u[x] + m[x - 1] + m[x + 1] + d[x]) + 4 * m[x];
      values->push_back(static_cast<float>(std::abs(response)));
    }
  }
}

// The noise sigma from the samples of NoiseSamples (reordered); 0 without any.
double NoiseSigmaOf(std::vector<float>* values) {
  if (values->empty()) return 0.0;
  const auto mid = values->begin() + static_cast<std::ptrdiff_t>(values->size() / 2);
  std::nth_element(values->begin(), mid, values->end());
  return 1.4826 * *mid / 6.0;  // the kernel's norm is 6
}

// The four directions of the shape test: x, y and the two diagonals.
enum class Direction { kX, kY, kDiagonalDown, kDiagonalUp };

// A line structuring element of `length` pixels along `d`, anchored at `anchor`
// (index along the line; -1 = centre).
cv::Mat LineElement(Direction d, int length, int anchor, cv::Point* anchor_point) {
  const int a = anchor < 0 ? length / 2 : anchor;
  switch (d) {
    case Direction::kX:
      *anchor_point = cv::Point(a, 0);
      return cv::Mat::ones(1, length, CV_8U);
    case Direction::kY:
      *anchor_point = cv::Point(0, a);
      return cv::Mat::ones(length, 1, CV_8U);
    case Direction::kDiagonalDown:
      *anchor_point = cv::Point(a, a);
      return cv::Mat::eye(length, length, CV_8U);
    case Direction::kDiagonalUp: {
      cv::Mat e;
      cv::flip(cv::Mat::eye(length, length, CV_8U), e, 1);  // (i, length - 1 - i)
      *anchor_point = cv::Point(length - 1 - a, a);
      return e;
    }
  }
  return {};
}

// The shape test along one direction: its step v = (vx, vy) (vy >= 0), the
// reach r of the grounds and the structuring elements of the minimum over
// p .. p + r v ("after") and of the maximum over p - peak_r v .. p + peak_r v
// ("peak").
struct ShapeElements {
  int vx = 0, vy = 0, r = 0;
  cv::Mat after, peak;
  cv::Point after_anchor, peak_anchor;
};

ShapeElements MakeShapeElements(Direction d, int r, int peak_r) {
  ShapeElements e;
  switch (d) {
    case Direction::kX:
      e.vx = 1, e.vy = 0;
      break;
    case Direction::kY:
      e.vx = 0, e.vy = 1;
      break;
    case Direction::kDiagonalDown:
      e.vx = 1, e.vy = 1;
      break;
    case Direction::kDiagonalUp:
      e.vx = -1, e.vy = 1;
      break;  // its element runs (-1, 1)
  }
  e.r = r;
  e.after = LineElement(d, r + 1, 0, &e.after_anchor);
  e.peak = LineElement(d, 2 * peak_r + 1, -1, &e.peak_anchor);
  return e;
}

// Thesis-independent shape test of DetectByHessian along one direction, on
// rows y0 .. y1 - 1 of the smoothed image f: sets 255 in *shaped (CV_8UC1,
// those rows) where, along d, the pixel rises at least `fraction` of the way
// from the ground (the higher of the darkest values within r steps before
// and after it, so that a stripe must have dark ground on both sides and an
// edge does not) to the peak (the brightest value within peak_r steps), and
// the peak stands at least min_contrast above the ground; other pixels are
// left as they are. Borders are replicated.
//
// The ground before p is the ground after p - r v: one erosion serves both,
// taken from r |vy| rows above the band; pixels whose p - r v falls outside
// the image take theirs directly.
void ShapeTestInto(const cv::Mat& f, int y0, int y1, const ShapeElements& e, float fraction,
                   float min_contrast, cv::Mat* shaped) {
  const int rows = f.rows, cols = f.cols, r = e.r;
  const int a = std::max(0, y0 - r * e.vy);  // first row of `after`
  cv::Mat after, peak;
  cv::erode(f.rowRange(a, y1), after, e.after, e.after_anchor, 1, cv::BORDER_REPLICATE);
  cv::dilate(f.rowRange(y0, y1), peak, e.peak, e.peak_anchor, 1, cv::BORDER_REPLICATE);
  std::vector<float> before(static_cast<size_t>(cols));
  // The columns where p - r v lies inside the image (for rows y >= r vy).
  const int inside_from = std::max(0, r * e.vx), inside_to = std::min(cols, cols + r * e.vx);
  for (int y = y0; y < y1; ++y) {
    const float* fr = f.ptr<float>(y);
    const float* ar = after.ptr<float>(y - a);
    const float* pr = peak.ptr<float>(y - y0);
    float* br = before.data();
    const int yb = y - r * e.vy;  // the row of p - r v
    int from = inside_from, to = inside_to;
    if (yb < 0 || from >= to) from = to = cols;  // none inside
    if (from < to) {
      const float* row = after.ptr<float>(yb - a);  // column x - r vx is p - r v
      std::copy(row + (from - r * e.vx), row + (to - r * e.vx), br + from);
    }
    auto direct = [&](int x) {  // the minimum over p, p - v, ..., p - r v, replicated
      float m = fr[x];
      for (int k = 1; k <= r; ++k)
        m = std::min(m, f.at<float>(std::clamp(y - k * e.vy, 0, rows - 1),
                                    std::clamp(x - k * e.vx, 0, cols - 1)));
      return m;
    };
    for (int x = 0; x < from; ++x) br[x] = direct(x);
    for (int x = to; x < cols; ++x) br[x] = direct(x);
    unsigned char* o = shaped->ptr<unsigned char>(y - y0);
    int x = 0;
#if CV_SIMD128
    const cv::v_float32x4 vfraction = cv::v_setall_f32(fraction),
                          vmin = cv::v_setall_f32(min_contrast);
    auto pass = [&](int i) {  // the test at columns i .. i + 3, as a lane mask
      const cv::v_float32x4 ground = cv::v_max(cv::v_load(br + i), cv::v_load(ar + i));
      const cv::v_float32x4 rise = cv::v_load(pr + i) - ground;
      return cv::v_reinterpret_as_u32((rise >= vmin) &
                                      (cv::v_load(fr + i) >= ground + vfraction * rise));
    };
    for (; x + 16 <= cols; x += 16) {
      const cv::v_uint8x16 m = cv::v_pack_b(pass(x), pass(x + 4), pass(x + 8), pass(x + 12));
      cv::v_store(o + x, cv::v_load(o + x) | m);
    }
#endif
    for (; x < cols; ++x) {
      const float ground = std::max(br[x], ar[x]);
      const float rise = pr[x] - ground;
      if (rise >= min_contrast && fr[x] >= ground + fraction * rise) o[x] = 255;
    }
  }
}

// Seeds of DetectByHessian among the shaped pixels: strength at least
// 2 * min_ridge_contrast and at least high_threshold times the local ridge
// level (`level`: the strongest ridge within the window, floored at
// min_ridge_contrast). Thresholds are compared in float, as cv::compare does.
void SeedRows(const cv::Mat& strength, const cv::Mat& level, const cv::Mat& shaped,
              const StripeDetectParams& p, cv::Mat* seeds) {
  const float floor = static_cast<float>(p.min_ridge_contrast);
  const float high = static_cast<float>(p.high_threshold);
  const float absolute = static_cast<float>(2.0 * p.min_ridge_contrast);
  const int cols = strength.cols;
  for (int y = 0; y < strength.rows; ++y) {
    const float* sr = strength.ptr<float>(y);
    const float* lr = level.ptr<float>(y);
    const unsigned char* shr = shaped.ptr<unsigned char>(y);
    unsigned char* o = seeds->ptr<unsigned char>(y);
    int x = 0;
#if CV_SIMD128
    const cv::v_float32x4 vfloor = cv::v_setall_f32(floor), vhigh = cv::v_setall_f32(high),
                          vabsolute = cv::v_setall_f32(absolute);
    auto seed = [&](int i) {  // columns i .. i + 3 as a lane mask
      const cv::v_float32x4 s = cv::v_load(sr + i);
      const cv::v_float32x4 relative = s / cv::v_max(cv::v_load(lr + i), vfloor);
      return cv::v_reinterpret_as_u32((relative >= vhigh) & (s >= vabsolute));
    };
    for (; x + 16 <= cols; x += 16) {
      const cv::v_uint8x16 m = cv::v_pack_b(seed(x), seed(x + 4), seed(x + 8), seed(x + 12));
      cv::v_store(o + x, cv::v_load(shr + x) & m);
    }
#endif
    for (; x < cols; ++x) {
      const float relative = sr[x] / std::max(lr[x], floor);
      o[x] = relative >= high && sr[x] >= absolute ? shr[x] : 0;
    }
  }
}

cv::Mat DetectByHessian(const cv::Mat& grey, const StripeDetectParams& p,
                        const Cancellation& cancel) {
  // Band by band in parallel: the ridge strength, the image smoothed for the
  // shape test and the noise samples.
  const std::vector<double> scales = Scales(p);
  cv::Mat strength(grey.size(), CV_32F);
  cv::Mat level_f;
  if (!(p.level_sigma > 0.0))
    grey.convertTo(level_f, CV_32F);
  else
    level_f.create(grey.size(), CV_32F);
  const bool estimate_noise = !(p.noise_sigma > 0.0);
  std::vector<std::vector<float>> noise((grey.rows + internal::kBandRows - 1) /
                                        internal::kBandRows);
  // Once the caller asks to stop, the bands left skip their work (an
  // exception must not leave OpenCV's workers) and the stage stops after.
  internal::ForEachBand(grey.rows, [&](int y0, int y1) {
    if (cancel.Requested()) return;
    RidgeStrengthRows(grey, scales, y0, y1, &strength);
    if (p.level_sigma > 0.0) {
      cv::Mat rows = level_f.rowRange(y0, y1);
      internal::GaussianInto(grey.rowRange(y0, y1), p.level_sigma, BlurHalf(p.level_sigma), &rows);
    }
    if (estimate_noise) NoiseSamples(grey, y0, y1, &noise[y0 / internal::kBandRows]);
  });
  cancel.ThrowIfRequested("the ridge strength");
  double noise_sigma = p.noise_sigma;
  if (estimate_noise) {
    std::vector<float> all;
    for (const auto& band : noise) all.insert(all.end(), band.begin(), band.end());
    noise_sigma = NoiseSigmaOf(&all);
  }

  // Seeds: strong ridges, absolutely and relative to the strongest ridge
  // within the window (so that dim eyebrow stripes seed as well).
  // Width and shape: a stripe pixel passes the shape test across its stripe;
  // trying x, y and both diagonals needs no direction estimate and lets
  // T-junction centres pass along a diagonal.
  const cv::Mat window =
      cv::getStructuringElement(cv::MORPH_RECT, cv::Size(p.contrast_window, p.contrast_window));
  const int half_window = p.contrast_window / 2;
  const int peak_reach = static_cast<int>(std::ceil(p.max_scale + 1.0));
  const float min_rise =
      static_cast<float>(std::max(p.min_ridge_contrast, p.noise_factor * noise_sigma));
  const float fraction = static_cast<float>(p.level_fraction);
  std::vector<ShapeElements> elements;
  for (Direction d :
       {Direction::kX, Direction::kY, Direction::kDiagonalDown, Direction::kDiagonalUp}) {
    // Diagonal steps are sqrt(2) long: fewer of them for the same reach.
    const bool diagonal = d == Direction::kDiagonalDown || d == Direction::kDiagonalUp;
    const double step = diagonal ? std::sqrt(2.0) : 1.0;
    const int r = static_cast<int>(std::lround(half_window / step));
    const int pr = static_cast<int>(std::ceil(peak_reach / step));
    elements.push_back(MakeShapeElements(d, r, pr));
  }
  cv::Mat shaped(grey.size(), CV_8UC1), seeds(grey.size(), CV_8UC1);
  internal::ForEachBand(grey.rows, [&](int y0, int y1) {
    if (cancel.Requested()) return;
    const cv::Mat strength_rows = strength.rowRange(y0, y1);
    cv::Mat level;
    cv::dilate(strength_rows, level, window, cv::Point(-1, -1), 1, cv::BORDER_REPLICATE);
    cv::Mat shaped_rows = shaped.rowRange(y0, y1);
    shaped_rows.setTo(0);
    for (const ShapeElements& e : elements)
      ShapeTestInto(level_f, y0, y1, e, fraction, min_rise, &shaped_rows);
    cv::Mat seeds_rows = seeds.rowRange(y0, y1);
    SeedRows(strength_rows, level, shaped_rows, p, &seeds_rows);
  });
  cancel.ThrowIfRequested("the stripe shape test");
  // Stripes grow from the seeds through the shaped pixels.
  return internal::KeepComponentsTouching(shaped, seeds, cancel, "the stripe mask");
}

cv::Mat DetectByAdaptiveThreshold(const cv::Mat& grey, const StripeDetectParams& p) {
  cv::Mat f;
  grey.convertTo(f, CV_32F);
  f = Blur(f, p.adaptive_sigma);
  const cv::Size window(p.adaptive_window, p.adaptive_window);
  cv::Mat mean, mean_sq;
  cv::boxFilter(f, mean, CV_32F, window, cv::Point(-1, -1), true, cv::BORDER_REPLICATE);
  cv::boxFilter(f.mul(f), mean_sq, CV_32F, window, cv::Point(-1, -1), true, cv::BORDER_REPLICATE);
  cv::Mat mask(grey.size(), CV_8UC1);
  const float k = static_cast<float>(p.adaptive_k);
  const float min_std = static_cast<float>(p.adaptive_min_std);
  for (int y = 0; y < f.rows; ++y) {
    const float* fr = f.ptr<float>(y);
    const float* mr = mean.ptr<float>(y);
    const float* sr = mean_sq.ptr<float>(y);
    unsigned char* out = mask.ptr<unsigned char>(y);
    for (int x = 0; x < f.cols; ++x) {
      const float sd = std::sqrt(std::max(0.0f, sr[x] - mr[x] * mr[x]));
      out[x] = (sd >= min_std && fr[x] > mr[x] + k * sd) ? 255 : 0;
    }
  }
  return mask;
}

}  // namespace

bool StripeDetectParams::IsValid(std::string* error) const {
  auto fail = [error](const char* why) {
    if (error) *error = why;
    return false;
  };
  if (!(min_scale > 0.0 && min_scale <= 20.0)) return fail("min_scale must lie in (0, 20] px");
  if (!(max_scale >= min_scale && max_scale <= 20.0))
    return fail("max_scale must lie in [min_scale, 20] px");
  if (scale_count < 1 || scale_count > 16) return fail("scale_count must lie in 1..16");
  if (contrast_window < 3 || contrast_window % 2 == 0)
    return fail("contrast_window must be odd and >= 3");
  if (!(min_ridge_contrast > 0.0)) return fail("min_ridge_contrast must be > 0 grey levels");
  if (!(noise_sigma >= 0.0)) return fail("noise_sigma must be >= 0 (0 = estimate)");
  if (!(noise_factor >= 0.0)) return fail("noise_factor must be >= 0");
  if (!(level_sigma >= 0.0 && level_sigma <= 20.0))
    return fail("level_sigma must lie in [0, 20] px");
  if (!(level_fraction >= 0.0 && level_fraction < 1.0))
    return fail("level_fraction must lie in [0, 1)");
  if (!(high_threshold > 0.0 && high_threshold <= 1.0))
    return fail("high_threshold must lie in (0, 1]");
  if (!(adaptive_sigma > 0.0 && adaptive_sigma <= 20.0))
    return fail("adaptive_sigma must lie in (0, 20] px");
  if (adaptive_window < 3 || adaptive_window % 2 == 0)
    return fail("adaptive_window must be odd and >= 3");
  if (!(adaptive_min_std >= 0.0)) return fail("adaptive_min_std must be >= 0");
  if (!std::isfinite(adaptive_k)) return fail("adaptive_k must be finite");
  return true;
}

cv::Mat RidgeStrength(const cv::Mat& grey, const StripeDetectParams& params) {
  RequireGrey8(grey, "RidgeStrength");
  RequireValid(params, "RidgeStrength");
  return ComputeRidgeStrength(grey, params);
}

cv::Mat DetectStripes(const cv::Mat& grey, const StripeDetectParams& params,
                      const Cancellation& cancel) {
  RequireGrey8(grey, "DetectStripes");
  RequireValid(params, "DetectStripes");
  if (params.method == StripeDetector::kAdaptiveThreshold)
    return DetectByAdaptiveThreshold(grey, params);
  return DetectByHessian(grey, params, cancel);
}

}  // namespace bsls::extraction
