#include "bsls/extraction/ridge_points.h"

#include <algorithm>
#include <stdexcept>

#include <opencv2/imgproc.hpp>

namespace bsls::extraction {

bool RidgeParams::IsValid(std::string* error) const {
  auto fail = [error](const char* why) {
    if (error) *error = why;
    return false;
  };
  if (half_window < 1 || half_window > 64) return fail("half_window must lie in 1..64");
  if (min_prominence < 1 || min_prominence > 255) return fail("min_prominence must lie in 1..255");
  return true;
}

std::span<const RidgePoint> RidgePoints::Row(int y) const {
  if (y < 0 || y + 1 >= static_cast<int>(row_start.size())) return {};
  return {points.data() + row_start[y], points.data() + row_start[y + 1]};
}

RidgePoints FindRidgePoints(const cv::Mat& smoothed, const RidgeParams& params) {
  if (smoothed.empty() || smoothed.type() != CV_8UC1)
    throw std::invalid_argument("FindRidgePoints: image must be a non-empty CV_8UC1 image");
  std::string why;
  if (!params.IsValid(&why)) throw std::invalid_argument("FindRidgePoints: " + why);

  // The darkest pixel within half_window to the left and to the right of
  // each pixel, and the brightest of its two neighbours and itself.
  const int w = params.half_window;
  const cv::Mat window = cv::Mat::ones(1, w + 1, CV_8U);
  cv::Mat left_min, right_min, peak, fall_left, fall_right, fall, candidates;
  cv::erode(smoothed, left_min, window, cv::Point(w, 0), 1, cv::BORDER_REPLICATE);
  cv::erode(smoothed, right_min, window, cv::Point(0, 0), 1, cv::BORDER_REPLICATE);
  cv::dilate(smoothed, peak, cv::Mat::ones(1, 3, CV_8U), cv::Point(1, 0), 1,
             cv::BORDER_REPLICATE);
  cv::subtract(smoothed, left_min, fall_left);
  cv::subtract(smoothed, right_min, fall_right);
  // Candidates: pixels no darker than their neighbours that fall far enough
  // on at least one side (every pixel of a peak's plateau shorter than about
  // half_window minus the stripe's edge does).
  cv::max(fall_left, fall_right, fall);
  cv::compare(smoothed, peak, candidates, cv::CMP_GE);
  cv::Mat strong;
  cv::compare(fall, params.min_prominence, strong, cv::CMP_GE);
  cv::bitwise_and(candidates, strong, candidates);
  std::vector<cv::Point> at;
  cv::findNonZero(candidates, at);

  RidgePoints out;
  out.points.reserve(at.size());
  out.row_start.assign(static_cast<size_t>(smoothed.rows) + 1, 0);
  int row = 0;
  const int last = smoothed.cols - 1;
  for (size_t i = 0; i < at.size();) {
    const int y = at[i].y;
    while (row <= y) out.row_start[row++] = static_cast<int>(out.points.size());
    const uchar* s = smoothed.ptr<uchar>(y);
    // A run of candidates of one grey level in one row: one peak or plateau.
    const int first = at[i].x;
    int end = first;
    size_t j = i + 1;
    while (j < at.size() && at[j].y == y && at[j].x == end + 1 && s[at[j].x] == s[first]) {
      end = at[j].x;
      ++j;
    }
    i = j;
    const int v = s[first];
    if (first == 0 || end == last || s[first - 1] >= v || s[end + 1] >= v) continue;
    const int prominence =
        std::min(fall_left.ptr<uchar>(y)[first], fall_right.ptr<uchar>(y)[end]);
    if (prominence < params.min_prominence) continue;
    float x;
    if (end > first) {
      x = 0.5f * static_cast<float>(first + end);
    } else {
      const float l = s[first - 1], r = s[first + 1];
      x = static_cast<float>(first) + 0.5f * (l - r) / (l - 2.0f * static_cast<float>(v) + r);
    }
    out.points.push_back({x, y, prominence});
  }
  while (row <= smoothed.rows) out.row_start[row++] = static_cast<int>(out.points.size());
  return out;
}

}  // namespace bsls::extraction
