// Private to bsls::simulator: the slide's transmission pre-rasterised at high
// resolution and blurred (projector blur), sampled bilinearly.
//
// Units: slide coordinates (s, t) and blur sigmas in line pitches d.
// Thread-safety: immutable after construction; Sample() may run concurrently.
#ifndef BSLS_SIMULATOR_SRC_SLIDE_RASTER_H_
#define BSLS_SIMULATOR_SRC_SLIDE_RASTER_H_

#include <opencv2/core.hpp>
#include <vector>

#include "bsls/pattern/brick_pattern.h"

namespace bsls::simulator {

struct SlideRasterParams {
  double samples_per_d = 32.0;      // raster resolution
  int antialias = 4;                // antialias x antialias InStroke samples per raster cell
  double blur_sigma_d = 0.05;       // blur of the sharpest level
  double max_blur_sigma_d = 0.05;   // blur of the blurriest level (> blur_sigma_d: several levels)
  double dark_transmission = 0.02;  // transmission of the opaque parts and outside the slide
};

class SlideRaster {
 public:
  // Rasterises `slide` (antialiased InStroke coverage) and blurs it to one or
  // more levels spanning [blur_sigma_d, max_blur_sigma_d].
  SlideRaster(const pattern::PatternSpec& spec, pattern::Slide slide,
              const SlideRasterParams& params);

  // Transmission in [dark, 1] at slide point (s, t) seen through a Gaussian
  // blur of `sigma_d`, clamped to the levels' range; levels are interpolated.
  double Sample(double s, double t, double sigma_d) const;

  // The sharpest level (CV_32FC1 transmission, rows along t) for inspection.
  const cv::Mat& sharpest() const { return levels_.front().image; }

 private:
  struct Level {
    cv::Mat image;        // CV_32FC1 transmission
    double rate_s = 0.0;  // cells per d along s (columns) and t (rows)
    double rate_t = 0.0;
    double sigma_d = 0.0;
    double s0 = 0.0;  // slide point of the centre of cell (0, 0)
    double t0 = 0.0;
  };
  double SampleLevel(const Level& level, double s, double t) const;

  double dark_ = 0.0;
  std::vector<Level> levels_;  // increasing sigma
};

}  // namespace bsls::simulator

#endif  // BSLS_SIMULATOR_SRC_SLIDE_RASTER_H_
