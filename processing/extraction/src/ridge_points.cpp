#include "bsls/extraction/ridge_points.h"

#include <algorithm>
#include <bit>
#include <stdexcept>

#include <opencv2/core.hpp>
#include <opencv2/core/hal/intrin.hpp>

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

namespace {

constexpr int kBandRows = 32;  // rows per parallel task

// The ridge points of one row `s` (cols pixels, read from s[-w] to
// s[cols - 1 + w + 16]: the caller pads it by replication), appended to
// `out` from left to right. `candidates` is scratch. Within w of the row's
// ends only the inner fall is judged.
void RowRidgePoints(const uchar* s, int cols, int y, const RidgeParams& params,
                    std::vector<int>* candidates, std::vector<RidgePoint>* out) {
  const int w = params.half_window;
  const int t = params.min_prominence;
  // The smaller fall within w to each side of x (the pixel's own grey level
  // minus the darkest one there).
  // The fall within w to each side of x: the pixel's own grey level minus
  // the darkest one there. Where the window is cut by the row's end, that
  // side is not judged (a stripe at the image's edge shows one flank only).
  constexpr int kUnjudged = 255;
  auto fall_left = [&](int x) {
    if (x < w) return kUnjudged;
    int lo = s[x];
    for (int k = 1; k <= w; ++k) lo = std::min<int>(lo, s[x - k]);
    return s[x] - lo;
  };
  auto fall_right = [&](int x) {
    if (x + w > cols - 1) return kUnjudged;
    int lo = s[x];
    for (int k = 1; k <= w; ++k) lo = std::min<int>(lo, s[x + k]);
    return s[x] - lo;
  };
  auto candidate = [&](int x) {
    return s[x] >= s[x - 1] && s[x] >= s[x + 1] && std::min(fall_left(x), fall_right(x)) >= t;
  };
  // Candidates: pixels no darker than their neighbours that fall by t on
  // both sides (every pixel of a peak's plateau does where the plateau is
  // shorter than about w minus the stripe's edge).
  candidates->clear();
  int x = 0;
  for (; x < std::min(w, cols); ++x)
    if (candidate(x)) candidates->push_back(x);
  const int inner_end = cols - w;  // from here the right window is cut
#if CV_SIMD128
  const cv::v_uint8x16 vt = cv::v_setall_u8(static_cast<uchar>(t));
  for (; x + 16 <= inner_end; x += 16) {
    const cv::v_uint8x16 v = cv::v_load(s + x);
    const cv::v_uint8x16 peak = (v >= cv::v_load(s + x - 1)) & (v >= cv::v_load(s + x + 1));
    if (!cv::v_check_any(peak)) continue;
    cv::v_uint8x16 left = v, right = v;
    for (int k = 1; k <= w; ++k) {
      left = cv::v_min(left, cv::v_load(s + x - k));
      right = cv::v_min(right, cv::v_load(s + x + k));
    }
    const cv::v_uint8x16 fall = cv::v_min(v - left, v - right);  // saturating
    unsigned mask = static_cast<unsigned>(cv::v_signmask(peak & (fall >= vt)));
    while (mask) {
      candidates->push_back(x + std::countr_zero(mask));
      mask &= mask - 1;
    }
  }
#endif
  for (; x < cols; ++x)
    if (candidate(x)) candidates->push_back(x);

  const std::vector<int>& at = *candidates;
  for (size_t i = 0; i < at.size();) {
    // A run of candidates of one grey level: one peak or plateau.
    const int first = at[i];
    int end = first;
    size_t j = i + 1;
    while (j < at.size() && at[j] == end + 1 && s[at[j]] == s[first]) {
      ++end;
      ++j;
    }
    i = j;
    const int v = s[first];
    // A peak at the row's end (a stripe cut by the image's edge) is taken
    // at that pixel.
    const bool at_edge = first == 0 || end == cols - 1;
    if ((first > 0 && s[first - 1] >= v) || (end < cols - 1 && s[end + 1] >= v)) continue;
    const int prominence = std::min(fall_left(first), fall_right(end));
    if (prominence < t || (at_edge && prominence == kUnjudged)) continue;
    float c;
    if (at_edge) {
      c = static_cast<float>(first == 0 ? first : end);
    } else if (end > first) {
      c = 0.5f * static_cast<float>(first + end);
    } else {
      const float l = s[first - 1], r = s[first + 1];
      c = static_cast<float>(first) + 0.5f * (l - r) / (l - 2.0f * static_cast<float>(v) + r);
    }
    out->push_back({c, y, prominence});
  }
}

}  // namespace

RidgePoints FindRidgePoints(const cv::Mat& smoothed, const RidgeParams& params) {
  if (smoothed.empty() || smoothed.type() != CV_8UC1)
    throw std::invalid_argument("FindRidgePoints: image must be a non-empty CV_8UC1 image");
  std::string why;
  if (!params.IsValid(&why)) throw std::invalid_argument("FindRidgePoints: " + why);

  // Rows are independent: bands of them in parallel (cv::parallel_for_),
  // each row copied into a buffer padded by replication.
  const int bands = (smoothed.rows + kBandRows - 1) / kBandRows;
  const int w = params.half_window, cols = smoothed.cols;
  constexpr int kVector = 16;  // the vector loop reads up to this far past a row's last pixel
  std::vector<std::vector<RidgePoint>> found(bands);
  cv::parallel_for_(cv::Range(0, bands), [&](const cv::Range& r) {
    std::vector<uchar> padded(static_cast<size_t>(cols + 2 * w + kVector));
    std::vector<int> candidates;
    for (int b = r.start; b < r.end; ++b) {
      const int y1 = std::min((b + 1) * kBandRows, smoothed.rows);
      for (int y = b * kBandRows; y < y1; ++y) {
        const uchar* row = smoothed.ptr<uchar>(y);
        std::fill(padded.begin(), padded.begin() + w, row[0]);
        std::copy(row, row + cols, padded.begin() + w);
        std::fill(padded.begin() + w + cols, padded.end(), row[cols - 1]);
        RowRidgePoints(padded.data() + w, cols, y, params, &candidates, &found[b]);
      }
    }
  });
  RidgePoints out;
  size_t total = 0;
  for (const auto& f : found) total += f.size();
  out.points.reserve(total);
  for (const auto& f : found) out.points.insert(out.points.end(), f.begin(), f.end());
  out.row_start.assign(static_cast<size_t>(smoothed.rows) + 1, 0);
  int row = 0;
  for (size_t i = 0; i < out.points.size(); ++i)
    while (row <= out.points[i].y) out.row_start[row++] = static_cast<int>(i);
  while (row <= smoothed.rows) out.row_start[row++] = static_cast<int>(out.points.size());
  return out;
}

}  // namespace bsls::extraction
