// Renders a Scene to an 8-bit grey image with exact ground truth: the slide
// (blurred by the projector, optionally with depth of field) lights the
// surfaces unless they are in the projector's shadow; the camera integrates
// n x n rays per pixel through its distorted model, blurs, and adds sensor
// noise (thesis 2.4-2.6: 512 x 512, 256 grey levels).
//
// Model per camera ray hitting a surface point X with albedo a:
//   E = ambient + power * T(s, t) * max(0, n . l) * falloff
//   grey = a * E * gain + black_level
// where T is the blurred slide transmission at the slide point (s, t) that
// lights X (dark_transmission on opaque parts), n the shading normal, l the
// direction to the projector and falloff = (focus_distance / |X - P|)^2 when
// enabled. Rays that hit nothing give black_level. The mean over the n x n
// rays is blurred (camera), noised, clamped to [0, 255] and rounded. Noise:
// Gaussian with variance noise_sigma^2 + shot_noise * max(0, grey - black_level)
// (read noise plus photon shot noise in its Gaussian approximation).
//
// Errors: the Renderer constructor (and so Render(scene, params)) throws
// std::invalid_argument naming the field when the scene or params are invalid.
//
// Thread-safety: a Renderer is immutable after construction; Render() may be
// called concurrently. Rendering itself runs rows in parallel (cv::parallel_for_).
#ifndef BSLS_SIMULATOR_RENDERER_H_
#define BSLS_SIMULATOR_RENDERER_H_

#include <cstdint>
#include <memory>
#include <opencv2/core.hpp>
#include <string>

#include "bsls/simulator/ground_truth.h"
#include "bsls/simulator/scene.h"

namespace bsls::simulator {

class SlideRaster;

struct RenderParams {
  int supersampling = 3;  // n: n x n camera rays per pixel, in [1, 8]

  // Projector.
  // Gaussian blur of the slide image at the focus distance, in line pitches d;
  // 0.05 d is about 0.6 px in the default 512 x 512 image.
  double projector_blur_sigma_d = 0.05;
  // Lens aperture diameter (mm) for depth of field; 0 = everything in focus.
  // The blur circle on the slide is A * f_d * |D - F| / (F * D) d for a point
  // at depth D along the projector axis, F = focus distance; its sigma (a
  // quarter of the diameter) adds in quadrature to projector_blur_sigma_d and
  // is capped at 0.6 d (the stripes are gone by then).
  double projector_aperture_mm = 0.0;
  double projector_focus_distance_mm = 730.0;  // along the projector axis, > 0
  double slide_samples_per_d = 32.0;           // slide raster resolution, [8, 128]
  int slide_antialias = 4;                     // InStroke samples per raster cell and axis, [1, 8]
  double dark_transmission = 0.02;             // of the opaque parts of the slide, [0, 1)
  double projector_power = 1.0;        // irradiance of an open slide at normal incidence, >= 0
  bool inverse_square_falloff = true;  // irradiance x (focus distance / distance)^2

  // Light and camera.
  double ambient = 0.03;              // irradiance from elsewhere, same units as power, >= 0
  double gain = 300.0;                // grey levels per unit of albedo x irradiance, > 0
  double black_level = 6.0;           // grey level of no light, [0, 255]
  double camera_blur_sigma_px = 0.5;  // Gaussian, pixels; 0 = none
  double noise_sigma = 3.0;           // additive Gaussian sensor noise, grey levels; 0 = none
  // Shot noise: variance in grey levels^2 per grey level above black_level
  // (the gain in grey levels per photo-electron), >= 0; 0 = none.
  double shot_noise = 0.0;
  std::uint32_t seed = 1;  // seeds the noise (std::mt19937)

  TruthParams truth;  // thresholds of the ground truth

  // True when every field is in range; otherwise names the field and the reason.
  bool IsValid(std::string* error) const;
};

// One rendered image and what is exactly known about it.
struct Frame {
  cv::Mat image;  // CV_8UC1, scene.height x scene.width
  GroundTruth truth;
};

// Renders one scene repeatedly; holds the rasterised, blurred slide.
class Renderer {
 public:
  // Copies the scene (surfaces are shared) and rasterises its slide.
  // Throws std::invalid_argument when the scene or params are invalid.
  Renderer(Scene scene, const RenderParams& params);
  ~Renderer();
  Renderer(Renderer&&) noexcept;
  Renderer& operator=(Renderer&&) noexcept;

  // The image with noise seeded by params().seed, and its ground truth.
  Frame Render() const;
  // The same with another noise seed (the noiseless image does not change).
  Frame Render(std::uint32_t seed) const;
  // The image only (no ground truth), noise seeded by `seed`.
  cv::Mat RenderImage(std::uint32_t seed) const;
  // Grey levels before noise, clamping and rounding (CV_32FC1), camera blur applied.
  cv::Mat RenderNoiseless() const;

  // The scene this renderer draws.
  const Scene& scene() const { return scene_; }
  // The params it was built with.
  const RenderParams& params() const { return params_; }

 private:
  double ProjectorBlurSigmaD(double depth_mm) const;

  Scene scene_;
  RenderParams params_;
  std::unique_ptr<const SlideRaster> raster_;
};

// One-shot: Renderer(scene, params).Render().
Frame Render(const Scene& scene, const RenderParams& params);

}  // namespace bsls::simulator

#endif  // BSLS_SIMULATOR_RENDERER_H_
