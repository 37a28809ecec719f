#include "bsls/interpretation/line_fill.h"

#include <cstdlib>
#include <stdexcept>

namespace bsls::interpretation {

// Thesis 5.2.2: Bresenham's line with an integer error term.
std::vector<cv::Point> BresenhamLine(cv::Point a, cv::Point b) {
  std::vector<cv::Point> out;
  const int dx = std::abs(b.x - a.x), dy = std::abs(b.y - a.y);
  const int sx = a.x < b.x ? 1 : -1, sy = a.y < b.y ? 1 : -1;
  out.reserve(std::max(dx, dy) + 1);
  cv::Point p = a;
  if (dy >= dx) {
    // y is the independent variable; the error starts at -dy/2.
    int error = -dy / 2;
    for (int i = 0; i <= dy; ++i) {
      out.push_back(p);
      p.y += sy;
      error += dx;
      if (error > 0) {
        p.x += sx;
        error -= dy;
      }
    }
  } else {
    int error = -dx / 2;
    for (int i = 0; i <= dx; ++i) {
      out.push_back(p);
      p.x += sx;
      error += dy;
      if (error > 0) {
        p.y += sy;
        error -= dx;
      }
    }
  }
  return out;
}

int FillGap(cv::Mat& skeleton, cv::Point a, cv::Point b) {
  if (skeleton.type() != CV_8UC1) throw std::invalid_argument("FillGap: skeleton must be CV_8UC1");
  int changed = 0;
  for (const cv::Point& p : BresenhamLine(a, b)) {
    if (p.x < 0 || p.y < 0 || p.x >= skeleton.cols || p.y >= skeleton.rows) continue;
    uchar& v = skeleton.at<uchar>(p);
    if (v == 0) {
      v = 255;
      ++changed;
    }
  }
  return changed;
}

}  // namespace bsls::interpretation
