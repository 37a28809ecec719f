// Synthetic test images with known geometry for the extraction tests.
//
// Coordinates: x = column, y = row, origin at the centre of the top-left
// pixel; pixel (c, r) covers [c - 0.5, c + 0.5] x [r - 0.5, r + 0.5].
#ifndef BSLS_TESTS_EXTRACTION_SYNTHETIC_IMAGES_H_
#define BSLS_TESTS_EXTRACTION_SYNTHETIC_IMAGES_H_

#include <cstdint>
#include <opencv2/core.hpp>
#include <vector>

namespace bsls::extraction::testing {

// One row of a vertical stripe (or one column of a horizontal one): the
// grey level of pixel i is background + contrast * integral over the pixel of
// (box of width `width` centred on `centre`) convolved with a Gaussian of
// `psf_sigma` (exact, via the integral of the normal CDF). No noise.
std::vector<double> RenderStripeProfile(int length, double centre, double width, double psf_sigma,
                                        double background, double contrast);

// A straight, nearly vertical stripe: centre x(y) = x0 + slope * y, width and
// psf measured perpendicular to the stripe; Gaussian noise of noise_sigma
// grey levels (seeded), rounded and saturated to CV_8UC1.
cv::Mat RenderSlantedStripe(cv::Size size, double x0, double slope, double width, double psf_sigma,
                            double background, double contrast, double noise_sigma,
                            std::uint32_t seed);

// The brick scene: vertical lines `pitch` apart, gently curved, joined by
// staggered horizontal segments (contracts section 1), on a dark ground,
// black outside an elliptic "face", with a dark low-albedo patch.
struct BrickScene {
  int width = 512;
  int height = 512;
  double pitch = 13.0;          // px between neighbouring vertical lines
  double row_pitch = 13.0;      // px between segment rows of neighbouring columns
  double first_x = 24.0;        // x of line 0 at the top
  double bend = 4.0;            // px, amplitude of the lines' sideways bend
  double min_line_width = 2.0;  // px; line p has width min + (p % 5) / 4 * (max - min)
  double max_line_width = 6.0;
  double segment_width = 3.0;  // px
  double psf_sigma = 0.8;      // px, optical blur
  double background = 25.0;    // grey level between the stripes inside the face
  double contrast = 120.0;     // stripe minus background, grey levels
  double noise_sigma = 3.0;    // grey levels
  bool dark_patch = true;      // albedo 0.3 ellipse (an eyebrow)
  double patch_albedo = 0.3;
  bool face_mask = true;  // black outside an ellipse
  std::uint32_t seed = 1;
};

// The known geometry of a rendered brick scene.
struct BrickTruth {
  int lines = 0;
  // line_x[p][y]: centre x of vertical line p at row y (may lie outside the image).
  std::vector<std::vector<double>> line_x;
  std::vector<double> line_width;
  // T-junctions (segment end on a line centre) inside the face and image.
  std::vector<cv::Point2d> junctions;
  cv::Mat inside;  // CV_8UC1, 255 where the face (and so the pattern) is visible
  cv::Mat dark;    // CV_8UC1, 255 inside the dark patch
  cv::Mat stroke;  // CV_8UC1, 255 where the (unblurred) pattern covers the pixel centre
  std::vector<double> segment_rows;  // y of every segment row (of some column)
  double segment_width = 0.0;
};

// Renders the scene (CV_8UC1) and its geometry.
cv::Mat RenderBrickScene(const BrickScene& scene, BrickTruth* truth);

// Rectangle-free helpers for thinning tests: a binary (0/255) vertical bar of
// `width` pixels (columns x0 .. x0 + width - 1) from row y0 to y1 inclusive.
cv::Mat BinaryBar(cv::Size size, int x0, int width, int y0, int y1);

// Number of 8-connected components of the non-zero pixels.
int CountComponents(const cv::Mat& binary);

// Number of 8-neighbours set around (x, y) of a binary image.
int Degree(const cv::Mat& binary, int x, int y);

}  // namespace bsls::extraction::testing

#endif  // BSLS_TESTS_EXTRACTION_SYNTHETIC_IMAGES_H_
