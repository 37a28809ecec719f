#include "bsls/simulator/renderer.h"

#include <algorithm>
#include <cmath>
#include <opencv2/core/utility.hpp>
#include <opencv2/imgproc.hpp>
#include <random>
#include <stdexcept>

#include "slide_raster.h"

namespace bsls::simulator {
namespace {

// Depth-of-field blur stops growing here (d): the stripes are gone by then.
constexpr double kMaxDefocusSigmaD = 0.6;
// A uniform blur disc of diameter c has a standard deviation of c / 4 per axis.
constexpr double kDiscDiameterToSigma = 0.25;

bool Fail(std::string* error, const std::string& why) {
  if (error) *error = why;
  return false;
}

bool NonNegativeFinite(double value) { return value >= 0.0 && std::isfinite(value); }

}  // namespace

bool RenderParams::IsValid(std::string* error) const {
  if (supersampling < 1 || supersampling > 8)
    return Fail(error, "render supersampling must lie in [1, 8]");
  if (!NonNegativeFinite(projector_blur_sigma_d) || projector_blur_sigma_d > kMaxDefocusSigmaD)
    return Fail(error, "render projector_blur_sigma_d must lie in [0, 0.6] d");
  if (!NonNegativeFinite(projector_aperture_mm))
    return Fail(error, "render projector_aperture_mm must be non-negative and finite");
  if (!(projector_focus_distance_mm > 0.0 && std::isfinite(projector_focus_distance_mm)))
    return Fail(error, "render projector_focus_distance_mm must be positive and finite");
  if (!(slide_samples_per_d >= 8.0 && slide_samples_per_d <= 128.0))
    return Fail(error, "render slide_samples_per_d must lie in [8, 128]");
  if (slide_antialias < 1 || slide_antialias > 8)
    return Fail(error, "render slide_antialias must lie in [1, 8]");
  if (!(dark_transmission >= 0.0 && dark_transmission < 1.0))
    return Fail(error, "render dark_transmission must lie in [0, 1)");
  if (!NonNegativeFinite(projector_power))
    return Fail(error, "render projector_power must be non-negative and finite");
  if (!NonNegativeFinite(ambient))
    return Fail(error, "render ambient must be non-negative and finite");
  if (!(gain > 0.0 && std::isfinite(gain)))
    return Fail(error, "render gain must be positive and finite");
  if (!(black_level >= 0.0 && black_level <= 255.0))
    return Fail(error, "render black_level must lie in [0, 255]");
  if (!NonNegativeFinite(camera_blur_sigma_px))
    return Fail(error, "render camera_blur_sigma_px must be non-negative and finite");
  if (!NonNegativeFinite(noise_sigma))
    return Fail(error, "render noise_sigma must be non-negative and finite");
  if (!NonNegativeFinite(shot_noise))
    return Fail(error, "render shot_noise must be non-negative and finite");
  std::string why;
  if (!truth.IsValid(&why)) return Fail(error, "render " + why);
  return true;
}

Renderer::Renderer(Scene scene, const RenderParams& params)
    : scene_(std::move(scene)), params_(params) {
  std::string error;
  if (!scene_.IsValid(&error)) throw std::invalid_argument("Renderer: " + error);
  if (!params_.IsValid(&error)) throw std::invalid_argument("Renderer: " + error);
  SlideRasterParams raster;
  raster.samples_per_d = params_.slide_samples_per_d;
  raster.antialias = params_.slide_antialias;
  raster.blur_sigma_d = params_.projector_blur_sigma_d;
  raster.max_blur_sigma_d = params_.projector_aperture_mm > 0.0
                                ? std::max(params_.projector_blur_sigma_d, kMaxDefocusSigmaD)
                                : params_.projector_blur_sigma_d;
  raster.dark_transmission = params_.dark_transmission;
  raster_ = std::make_unique<const SlideRaster>(scene_.pattern, scene_.slide, raster);
}

Renderer::~Renderer() = default;
Renderer::Renderer(Renderer&&) noexcept = default;
Renderer& Renderer::operator=(Renderer&&) noexcept = default;

double Renderer::ProjectorBlurSigmaD(double depth_mm) const {
  const double sigma0 = params_.projector_blur_sigma_d;
  if (params_.projector_aperture_mm <= 0.0 || depth_mm <= 0.0) return sigma0;
  const double focus = params_.projector_focus_distance_mm;
  const double focal_d = scene_.projector.intrinsics().fx;
  const double circle_d =
      params_.projector_aperture_mm * focal_d * std::abs(depth_mm - focus) / (focus * depth_mm);
  const double defocus = kDiscDiameterToSigma * circle_d;
  return std::min(std::sqrt(sigma0 * sigma0 + defocus * defocus), kMaxDefocusSigmaD);
}

cv::Mat Renderer::RenderNoiseless() const {
  const int n = params_.supersampling;
  const double focus = params_.projector_focus_distance_mm;
  cv::Mat grey(scene_.height, scene_.width, CV_32FC1);
  cv::parallel_for_(cv::Range(0, scene_.height), [&](const cv::Range& rows) {
    for (int y = rows.start; y < rows.end; ++y) {
      float* out = grey.ptr<float>(y);
      for (int x = 0; x < scene_.width; ++x) {
        double radiance = 0.0;
        for (int i = 0; i < n; ++i) {
          const double sy = y - 0.5 + (i + 0.5) / n;
          for (int k = 0; k < n; ++k) {
            const double sx = x - 0.5 + (k + 0.5) / n;
            const auto sample = scene_.TraceCameraRay(scene_.camera.BackProject({sx, sy}));
            if (!sample) continue;
            double irradiance = params_.ambient;
            if (sample->lit && sample->cos_incidence > 0.0) {
              const double transmission =
                  raster_->Sample(sample->slide_st.x(), sample->slide_st.y(),
                                  ProjectorBlurSigmaD(sample->projector_depth_mm));
              double falloff = 1.0;
              if (params_.inverse_square_falloff) {
                const double ratio = focus / sample->projector_distance_mm;
                falloff = ratio * ratio;
              }
              irradiance +=
                  params_.projector_power * transmission * sample->cos_incidence * falloff;
            }
            radiance += scene_.albedo.At(sample->hit.point) * irradiance;
          }
        }
        out[x] = static_cast<float>(radiance / (n * n) * params_.gain + params_.black_level);
      }
    }
  });
  if (params_.camera_blur_sigma_px > 0.0)
    cv::GaussianBlur(grey, grey, cv::Size(0, 0), params_.camera_blur_sigma_px,
                     params_.camera_blur_sigma_px, cv::BORDER_REPLICATE);
  return grey;
}

cv::Mat Renderer::RenderImage(std::uint32_t seed) const {
  cv::Mat grey = RenderNoiseless();
  if (params_.shot_noise > 0.0) {
    // Per-pixel sigma; the read-noise-only branch below keeps its exact draws.
    std::mt19937 rng(seed);
    std::normal_distribution<float> unit(0.0f, 1.0f);
    const double read_var = params_.noise_sigma * params_.noise_sigma;
    for (int y = 0; y < grey.rows; ++y) {
      float* row = grey.ptr<float>(y);
      for (int x = 0; x < grey.cols; ++x) {
        const double signal = std::max(0.0, row[x] - params_.black_level);
        row[x] += static_cast<float>(std::sqrt(read_var + params_.shot_noise * signal)) * unit(rng);
      }
    }
  } else if (params_.noise_sigma > 0.0) {
    std::mt19937 rng(seed);
    std::normal_distribution<float> noise(0.0f, static_cast<float>(params_.noise_sigma));
    for (int y = 0; y < grey.rows; ++y) {
      float* row = grey.ptr<float>(y);
      for (int x = 0; x < grey.cols; ++x) row[x] += noise(rng);
    }
  }
  cv::Mat image;
  grey.convertTo(image, CV_8UC1);  // rounds to nearest and saturates to [0, 255]
  return image;
}

Frame Renderer::Render(std::uint32_t seed) const {
  Frame frame;
  frame.image = RenderImage(seed);
  frame.truth = ComputeGroundTruth(scene_, params_.truth);
  return frame;
}

Frame Renderer::Render() const { return Render(params_.seed); }

Frame Render(const Scene& scene, const RenderParams& params) {
  return Renderer(scene, params).Render();
}

}  // namespace bsls::simulator
