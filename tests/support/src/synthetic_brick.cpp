#include "bsls/testing/synthetic_brick.h"

#include <cmath>
#include <opencv2/imgproc.hpp>

namespace bsls::testing {

cv::Point2d SyntheticBrick::Map(double u, double v) const {
  const SyntheticBrickParams& p = params;
  const int dir = pattern::ImageDirectionOfIncreasingP(p.side);
  const double y = p.centre_y + v * p.row_spacing + p.tilt * u * p.line_pitch;
  const double bow = p.bend * std::sin((y / p.size.height) * 3.14159265358979);
  const double x = p.line0_x + dir * u * p.line_pitch + bow;
  return {x, y};
}

SyntheticBrick DrawSyntheticBrick(const SyntheticBrickParams& params) {
  SyntheticBrick b;
  b.params = params;
  b.skeleton = cv::Mat::zeros(params.size, CV_8UC1);
  auto pt = [&](double u, double v) {
    const cv::Point2d q = b.Map(u, v);
    return cv::Point(cvRound(q.x), cvRound(q.y));
  };
  const double v_top = params.first_row - 0.45, v_bottom = params.last_row + 0.45;
  for (int p = 0; p < params.visible_lines; ++p) {
    // Lines as polylines through many points so the bow is followed.
    cv::Point prev = pt(p, v_top);
    for (double v = v_top + 0.1; v <= v_bottom + 1e-9; v += 0.1) {
      const cv::Point cur = pt(p, v);
      cv::line(b.skeleton, prev, cur, 255, 1, cv::LINE_8);
      prev = cur;
    }
  }
  for (int p = 0; p + 1 < params.visible_lines; ++p) {
    for (int v = params.first_row; v <= params.last_row; ++v) {
      if (((v - p) % 2 + 2) % 2 != 0) continue;
      cv::line(b.skeleton, pt(p, v), pt(p + 1, v), 255, 1, cv::LINE_8);
    }
  }
  for (int p = 0; p < params.visible_lines; ++p) {
    for (int v = params.first_row; v <= params.last_row; ++v) {
      const bool direct_row = ((v - p) % 2 + 2) % 2 == 0;
      pattern::JunctionKind kind;
      if (direct_row && p + 1 < params.visible_lines)
        kind = pattern::JunctionKind::kDirect;
      else if (!direct_row && p >= 1)
        kind = pattern::JunctionKind::kCorresponding;
      else
        continue;
      const cv::Point q = pt(p, v);
      b.junctions.push_back({p, v, kind, cv::Point2d(q.x, q.y)});
    }
  }
  return b;
}

cv::Mat RenderGrey(const SyntheticBrick& brick, double noise_sigma, unsigned seed) {
  cv::Mat strokes, grey;
  cv::dilate(brick.skeleton, strokes, cv::getStructuringElement(cv::MORPH_RECT, {3, 3}));
  strokes.convertTo(grey, CV_32F, 180.0 / 255.0, 20.0);
  cv::GaussianBlur(grey, grey, cv::Size(0, 0), 1.0);
  cv::Mat noise(grey.size(), CV_32F);
  cv::RNG rng(seed);
  rng.fill(noise, cv::RNG::NORMAL, 0.0, noise_sigma);
  grey += noise;
  cv::Mat out;
  grey.convertTo(out, CV_8U);
  return out;
}

void CutAwayLineZero(SyntheticBrick& brick) {
  const cv::Point2d l0 = brick.Map(0, 0), l1 = brick.Map(1, 0);
  // Line 0 lies opposite to increasing p: the cut keeps 3 px of the middle on line 1's side.
  const int towards_p = pattern::ImageDirectionOfIncreasingP(brick.params.side);
  const int cut = cvRound((l0.x + l1.x) / 2 - 3 * towards_p);
  if (towards_p < 0)
    brick.skeleton.colRange(cut, brick.skeleton.cols).setTo(0);
  else
    brick.skeleton.colRange(0, cut + 1).setTo(0);
}

const TruthJunction* FindTruth(const SyntheticBrick& brick, int p, int v) {
  for (const TruthJunction& j : brick.junctions)
    if (j.p == p && j.v == v) return &j;
  return nullptr;
}

void EraseDisk(cv::Mat& skeleton, cv::Point2d centre, double radius) {
  for (int y = static_cast<int>(centre.y - radius) - 1; y <= centre.y + radius + 1; ++y)
    for (int x = static_cast<int>(centre.x - radius) - 1; x <= centre.x + radius + 1; ++x)
      if (x >= 0 && y >= 0 && x < skeleton.cols && y < skeleton.rows &&
          std::hypot(x - centre.x, y - centre.y) <= radius)
        skeleton.at<uchar>(y, x) = 0;
}

void EraseLineBetween(SyntheticBrick& brick, int p, double v0, double v1) {
  const cv::Point2d a = brick.Map(p, v0), c = brick.Map(p, v1);
  for (int y = static_cast<int>(std::ceil(a.y)); y <= static_cast<int>(std::floor(c.y)); ++y) {
    const double t = (y - a.y) / (c.y - a.y);
    const int x = cvRound(a.x + t * (c.x - a.x));
    for (int dx = -2; dx <= 2; ++dx)
      if (x + dx >= 0 && x + dx < brick.skeleton.cols && y >= 0 && y < brick.skeleton.rows)
        brick.skeleton.at<uchar>(y, x + dx) = 0;
  }
}

void EraseSegmentMiddle(SyntheticBrick& brick, int p, int v, double fraction) {
  const cv::Point2d a = brick.Map(p + 0.5 - fraction / 2, v);
  const cv::Point2d c = brick.Map(p + 0.5 + fraction / 2, v);
  const int x0 = static_cast<int>(std::min(a.x, c.x)), x1 = static_cast<int>(std::max(a.x, c.x));
  for (int x = x0; x <= x1; ++x) {
    const double t = (x - a.x) / (c.x - a.x);
    const int y = cvRound(a.y + t * (c.y - a.y));
    for (int dy = -2; dy <= 2; ++dy)
      if (y + dy >= 0 && y + dy < brick.skeleton.rows) brick.skeleton.at<uchar>(y + dy, x) = 0;
  }
}

}  // namespace bsls::testing
