#include "slide_raster.h"

#include <algorithm>
#include <cmath>
#include <opencv2/core/utility.hpp>
#include <opencv2/imgproc.hpp>

namespace bsls::simulator {
namespace {

// Successive blur levels differ by this factor in sigma.
constexpr double kLevelRatio = 1.25;
// Smallest sigma step between levels, d (keeps sigma0 = 0 usable).
constexpr double kMinLevelSigmaD = 0.02;
// Blurred levels keep at least this many samples per sigma.
constexpr double kSamplesPerSigma = 6.0;
// Margin around the drawn slide, in sigmas of the blurriest level plus cells.
constexpr double kMarginSigmas = 4.0;
constexpr double kMarginD = 0.25;

}  // namespace

SlideRaster::SlideRaster(const pattern::PatternSpec& spec, pattern::Slide slide,
                         const SlideRasterParams& params)
    : dark_(params.dark_transmission) {
  const double half = spec.stroke_width / 2.0;
  const double last = spec.lines - 1 + half;
  double s_min = -last, s_max = last;
  if (slide == pattern::Slide::kLeftBrick) s_max = half;    // u = -s in [0, N-1]
  if (slide == pattern::Slide::kRightBrick) s_min = -half;  // u = s
  const double t_max = spec.rows + half;
  const double max_sigma = std::max(params.blur_sigma_d, params.max_blur_sigma_d);
  const double margin = kMarginSigmas * max_sigma + kMarginD;
  // Cell centres sit on multiples of 1 / spd: the raster of the right slide is
  // then the exact mirror of the left one, and every stroke is sampled at the
  // same phase (no sampling bias between lines).
  const double spd = params.samples_per_d;
  s_min = std::floor((s_min - margin) * spd) / spd;
  s_max = std::ceil((s_max + margin) * spd) / spd;
  const double t_min = std::floor((-t_max - margin) * spd) / spd;
  const double t_hi = std::ceil((t_max + margin) * spd) / spd;

  // Antialiased coverage at the base resolution.
  const int cols = static_cast<int>(std::lround((s_max - s_min) * spd)) + 1;
  const int rows = static_cast<int>(std::lround((t_hi - t_min) * spd)) + 1;
  cv::Mat coverage(rows, cols, CV_32FC1);
  const int aa = std::max(1, params.antialias);
  cv::parallel_for_(cv::Range(0, rows), [&](const cv::Range& range) {
    for (int r = range.start; r < range.end; ++r) {
      float* out = coverage.ptr<float>(r);
      for (int c = 0; c < cols; ++c) {
        int inside = 0;
        for (int i = 0; i < aa; ++i) {
          const double t = t_min + (r + (i + 0.5) / aa - 0.5) / spd;
          for (int k = 0; k < aa; ++k) {
            const double s = s_min + (c + (k + 0.5) / aa - 0.5) / spd;
            inside += pattern::InStroke(spec, slide, s, t) ? 1 : 0;
          }
        }
        out[c] = static_cast<float>(inside) / static_cast<float>(aa * aa);
      }
    }
  });

  std::vector<double> sigmas{params.blur_sigma_d};
  while (sigmas.back() < max_sigma) {
    const double next = std::max(sigmas.back() * kLevelRatio, sigmas.back() + kMinLevelSigmaD);
    sigmas.push_back(std::min(next, max_sigma));
  }
  for (const double sigma : sigmas) {
    Level level;
    level.sigma_d = sigma;
    cv::Mat blurred;
    if (sigma * spd > 0.05) {
      cv::GaussianBlur(coverage, blurred, cv::Size(0, 0), sigma * spd, sigma * spd,
                       cv::BORDER_REPLICATE);
    } else {
      blurred = coverage.clone();
    }
    // Blurrier levels need fewer samples: shrink (area average, edges kept).
    const double wanted = std::min(spd, std::max(4.0, kSamplesPerSigma / std::max(sigma, 1e-9)));
    level.rate_s = level.rate_t = spd;
    if (wanted < spd) {
      const int level_cols = std::max(2, static_cast<int>(std::ceil(cols * wanted / spd)));
      const int level_rows = std::max(2, static_cast<int>(std::ceil(rows * wanted / spd)));
      cv::resize(blurred, blurred, cv::Size(level_cols, level_rows), 0, 0, cv::INTER_AREA);
      level.rate_s = level_cols * spd / cols;
      level.rate_t = level_rows * spd / rows;
    }
    // The raster spans [s_min - 0.5/spd, s_min + (cols - 0.5)/spd] at every level.
    level.s0 = s_min - 0.5 / spd + 0.5 / level.rate_s;
    level.t0 = t_min - 0.5 / spd + 0.5 / level.rate_t;
    blurred.convertTo(level.image, CV_32FC1, 1.0 - dark_, dark_);
    levels_.push_back(std::move(level));
  }
}

double SlideRaster::SampleLevel(const Level& level, double s, double t) const {
  const double x = (s - level.s0) * level.rate_s;
  const double y = (t - level.t0) * level.rate_t;
  if (!(x >= 0.0 && y >= 0.0 && x <= level.image.cols - 1 && y <= level.image.rows - 1))
    return dark_;
  const int x0 = std::min(static_cast<int>(x), level.image.cols - 2);
  const int y0 = std::min(static_cast<int>(y), level.image.rows - 2);
  const double fx = x - x0;
  const double fy = y - y0;
  const float* r0 = level.image.ptr<float>(y0);
  const float* r1 = level.image.ptr<float>(y0 + 1);
  const double top = r0[x0] + fx * (r0[x0 + 1] - r0[x0]);
  const double bottom = r1[x0] + fx * (r1[x0 + 1] - r1[x0]);
  return top + fy * (bottom - top);
}

double SlideRaster::Sample(double s, double t, double sigma_d) const {
  if (levels_.size() == 1 || sigma_d <= levels_.front().sigma_d)
    return SampleLevel(levels_.front(), s, t);
  if (sigma_d >= levels_.back().sigma_d) return SampleLevel(levels_.back(), s, t);
  size_t k = 1;
  while (levels_[k].sigma_d < sigma_d) ++k;
  const Level& lo = levels_[k - 1];
  const Level& hi = levels_[k];
  const double w = (sigma_d - lo.sigma_d) / (hi.sigma_d - lo.sigma_d);
  return (1.0 - w) * SampleLevel(lo, s, t) + w * SampleLevel(hi, s, t);
}

}  // namespace bsls::simulator
