#include "synthetic_images.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <opencv2/imgproc.hpp>
#include <random>

namespace bsls::extraction::testing {
namespace {

double Phi(double u) { return 0.5 * std::erfc(-u / std::numbers::sqrt2); }
double phi(double u) { return std::exp(-0.5 * u * u) / std::sqrt(2.0 * std::numbers::pi); }
// Antiderivative of Phi.
double Psi(double u) { return u * Phi(u) + phi(u); }

// Mean over [t1, t2] of the box [a - w/2, a + w/2] blurred by a Gaussian of sigma.
double BlurredBoxMean(double t1, double t2, double a, double w, double sigma) {
  auto integral = [&](double edge) {  // integral of Phi((t - edge) / sigma) over [t1, t2]
    return sigma * (Psi((t2 - edge) / sigma) - Psi((t1 - edge) / sigma));
  };
  return (integral(a - 0.5 * w) - integral(a + 0.5 * w)) / (t2 - t1);
}

double SmoothStep(double e0, double e1, double v) {
  const double t = std::clamp((v - e0) / (e1 - e0), 0.0, 1.0);
  return t * t * (3.0 - 2.0 * t);
}

}  // namespace

std::vector<double> RenderStripeProfile(int length, double centre, double width, double psf_sigma,
                                        double background, double contrast) {
  std::vector<double> out(static_cast<size_t>(length));
  for (int i = 0; i < length; ++i)
    out[static_cast<size_t>(i)] =
        background + contrast * BlurredBoxMean(i - 0.5, i + 0.5, centre, width, psf_sigma);
  return out;
}

cv::Mat RenderSlantedStripe(cv::Size size, double x0, double slope, double width, double psf_sigma,
                            double background, double contrast, double noise_sigma,
                            std::uint32_t seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> noise(0.0, noise_sigma);
  const double stretch = std::sqrt(1.0 + slope * slope);  // perpendicular -> horizontal
  cv::Mat out(size, CV_8UC1);
  constexpr int kSubRows = 5;
  for (int y = 0; y < size.height; ++y) {
    std::vector<double> row(static_cast<size_t>(size.width), 0.0);
    for (int s = 0; s < kSubRows; ++s) {
      const double sy = y - 0.5 + (s + 0.5) / kSubRows;
      const auto profile = RenderStripeProfile(size.width, x0 + slope * sy, width * stretch,
                                               psf_sigma * stretch, background, contrast);
      for (int x = 0; x < size.width; ++x)
        row[static_cast<size_t>(x)] += profile[static_cast<size_t>(x)] / kSubRows;
    }
    for (int x = 0; x < size.width; ++x)
      out.at<unsigned char>(y, x) =
          cv::saturate_cast<unsigned char>(row[static_cast<size_t>(x)] + noise(rng));
  }
  return out;
}

cv::Mat RenderBrickScene(const BrickScene& scene, BrickTruth* truth) {
  const int W = scene.width;
  const int H = scene.height;
  int lines = 0;
  while (scene.first_x + lines * scene.pitch < W - scene.first_x + scene.bend) ++lines;
  std::vector<double> widths(static_cast<size_t>(lines));
  for (int p = 0; p < lines; ++p)
    widths[static_cast<size_t>(p)] =
        scene.min_line_width + (p % 5) / 4.0 * (scene.max_line_width - scene.min_line_width);
  auto bend = [&](double y) { return scene.bend * std::sin(std::numbers::pi * y / H); };
  auto line_x = [&](int p, double y) { return scene.first_x + p * scene.pitch + bend(y); };
  auto segment_y = [&](int v) { return 0.5 * scene.row_pitch + v * scene.row_pitch; };

  auto covered = [&](double sx, double sy) {
    const double u = (sx - scene.first_x - bend(sy)) / scene.pitch;  // line units
    const int p = static_cast<int>(std::lround(u));
    if (p >= 0 && p < lines && std::abs(sx - line_x(p, sy)) <= 0.5 * widths[static_cast<size_t>(p)])
      return true;
    const int column = static_cast<int>(std::floor(u));
    if (column < 0 || column >= lines - 1) return false;
    const int v = static_cast<int>(std::lround((sy - 0.5 * scene.row_pitch) / scene.row_pitch));
    if (v < 0 || ((v - column) % 2) != 0) return false;
    return std::abs(sy - segment_y(v)) <= 0.5 * scene.segment_width;
  };

  // Stroke coverage by 4 x 4 supersampling, then the optical blur.
  cv::Mat coverage(H, W, CV_32F);
  cv::Mat stroke(H, W, CV_8UC1);
  for (int y = 0; y < H; ++y)
    for (int x = 0; x < W; ++x) {
      int hits = 0;
      for (int j = 0; j < 4; ++j)
        for (int i = 0; i < 4; ++i)
          hits += covered(x - 0.375 + 0.25 * i, y - 0.375 + 0.25 * j) ? 1 : 0;
      coverage.at<float>(y, x) = hits / 16.0f;
      stroke.at<unsigned char>(y, x) = covered(x, y) ? 255 : 0;
    }
  cv::Mat blurred;
  cv::GaussianBlur(coverage, blurred, cv::Size(0, 0), scene.psf_sigma, scene.psf_sigma,
                   cv::BORDER_REPLICATE);

  // Face ellipse with a soft rim, shading, dark patch, noise.
  const double cx = 0.5 * (W - 1), cy = 0.5 * (H - 1);
  const double ax = 0.46 * W, ay = 0.48 * H;
  const double px = 0.36 * W, py = 0.30 * H, pax = 0.13 * W, pay = 0.055 * H;
  cv::Mat inside(H, W, CV_8UC1), dark(H, W, CV_8UC1);
  cv::Mat image(H, W, CV_8UC1);
  std::mt19937 rng(scene.seed);
  std::normal_distribution<double> noise(0.0, scene.noise_sigma);
  for (int y = 0; y < H; ++y)
    for (int x = 0; x < W; ++x) {
      const double r = std::hypot((x - cx) / ax, (y - cy) / ay);
      const double face = scene.face_mask ? 1.0 - SmoothStep(0.97, 1.0, r) : 1.0;
      const double rp = std::hypot((x - px) / pax, (y - py) / pay);
      const double albedo =
          scene.dark_patch ? 1.0 - (1.0 - scene.patch_albedo) * (1.0 - SmoothStep(0.8, 1.0, rp))
                           : 1.0;
      const double shading = 0.7 + 0.3 * std::cos(std::numbers::pi * (x - cx) / W);
      const double value =
          face * albedo * shading * (scene.background + scene.contrast * blurred.at<float>(y, x));
      image.at<unsigned char>(y, x) = cv::saturate_cast<unsigned char>(value + noise(rng));
      inside.at<unsigned char>(y, x) = face > 0.99 ? 255 : 0;
      dark.at<unsigned char>(y, x) = rp < 1.0 && scene.dark_patch ? 255 : 0;
    }

  if (truth) {
    truth->lines = lines;
    truth->line_width = widths;
    truth->line_x.assign(static_cast<size_t>(lines), std::vector<double>(static_cast<size_t>(H)));
    for (int p = 0; p < lines; ++p)
      for (int y = 0; y < H; ++y)
        truth->line_x[static_cast<size_t>(p)][static_cast<size_t>(y)] = line_x(p, y);
    truth->junctions.clear();
    cv::Mat inner;
    cv::erode(inside, inner, cv::getStructuringElement(cv::MORPH_ELLIPSE, cv::Size(17, 17)));
    for (int column = 0; column + 1 < lines; ++column)
      for (int v = 0; segment_y(v) < H; ++v) {
        if ((v - column) % 2 != 0) continue;
        const double y = segment_y(v);
        for (int p : {column, column + 1}) {
          const cv::Point2d j(line_x(p, y), y);
          const int ix = static_cast<int>(std::lround(j.x));
          const int iy = static_cast<int>(std::lround(j.y));
          if (ix < 0 || iy < 0 || ix >= W || iy >= H) continue;
          if (inner.at<unsigned char>(iy, ix)) truth->junctions.push_back(j);
        }
      }
    truth->segment_rows.clear();
    for (int v = 0; segment_y(v) < H; ++v) truth->segment_rows.push_back(segment_y(v));
    truth->segment_width = scene.segment_width;
    truth->inside = inside;
    truth->dark = dark;
    truth->stroke = stroke;
  }
  return image;
}

cv::Mat BinaryBar(cv::Size size, int x0, int width, int y0, int y1) {
  cv::Mat out = cv::Mat::zeros(size, CV_8UC1);
  out(cv::Rect(x0, y0, width, y1 - y0 + 1)).setTo(255);
  return out;
}

int CountComponents(const cv::Mat& binary) {
  cv::Mat labels;
  return cv::connectedComponents(binary != 0, labels, 8, CV_32S) - 1;
}

int Degree(const cv::Mat& binary, int x, int y) {
  int n = 0;
  for (int dy = -1; dy <= 1; ++dy)
    for (int dx = -1; dx <= 1; ++dx) {
      if (dx == 0 && dy == 0) continue;
      const int xx = x + dx, yy = y + dy;
      if (xx < 0 || yy < 0 || xx >= binary.cols || yy >= binary.rows) continue;
      if (binary.at<unsigned char>(yy, xx)) ++n;
    }
  return n;
}

}  // namespace bsls::extraction::testing
