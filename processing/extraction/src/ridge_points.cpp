#include "bsls/extraction/ridge_points.h"

#include <algorithm>
#include <bit>
#include <opencv2/core.hpp>
#include <opencv2/core/hal/intrin.hpp>
#include <stdexcept>

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

constexpr int kBandRows = 32;   // rows per parallel task
constexpr int kVector = 16;     // pixels per vector step
constexpr int kUnjudged = 255;  // the fall of a side cut by the image's edge

// One row or column of the smoothed image as a profile: value(i) for
// i in 0 .. n-1, replicated beyond.
struct Profile {
  const uchar* data;
  std::ptrdiff_t step;  // bytes between consecutive pixels
  int n;

  int operator()(int i) const { return data[std::clamp(i, 0, n - 1) * step]; }
  // Pixel i, which must lie in 0 .. n-1.
  int At(int i) const { return data[i * step]; }
};

// The fall within w to one side of i (dir = -1 before, +1 after): the
// pixel's own grey level minus the darkest one there. Where the window is
// cut by the profile's end, that side is not judged (a stripe at the image's
// edge shows one flank only).
int Fall(const Profile& s, int i, int dir, int w) {
  if (i + dir * w < 0 || i + dir * w > s.n - 1) return kUnjudged;
  const uchar* p = s.data + i * s.step;
  const std::ptrdiff_t d = dir * s.step;
  int lo = p[0];
  for (int k = 1; k <= w; ++k) lo = std::min<int>(lo, p[k * d]);
  return p[0] - lo;
}

// A candidate pixel: no darker than its neighbours, falling by t on both
// sides (every pixel of a peak's plateau does where the plateau is shorter
// than about w minus the stripe's edge), with its two falls.
struct Candidate {
  int at;
  uchar before, after;
};

// Appends pixel i of `s` to `out` when it is a candidate.
void AddIfCandidate(const Profile& s, int i, int w, int t, std::vector<Candidate>* out) {
  if (s(i) < s(i - 1) || s(i) < s(i + 1)) return;
  const int before = Fall(s, i, -1, w), after = Fall(s, i, +1, w);
  if (std::min(before, after) >= t)
    out->push_back({i, static_cast<uchar>(before), static_cast<uchar>(after)});
}

// The ridge points of profile `s` (row or column `line` of the image) from
// its candidates in increasing order, appended to `out`: each run of
// candidates of one grey level is one peak or plateau.
void ProfileRidgePoints(const Profile& s, int line, const std::vector<Candidate>& at, int t,
                        std::vector<RidgePoint>* out) {
  for (size_t i = 0; i < at.size();) {
    const int first = at[i].at;
    const int v = s.At(first);
    int end = first;
    size_t j = i + 1;
    while (j < at.size() && at[j].at == end + 1 && s.At(at[j].at) == v) {
      ++end;
      ++j;
    }
    const int prominence = std::min(at[i].before, at[j - 1].after);
    i = j;
    // A peak at the profile's end (a stripe cut by the image's edge) is
    // taken at that pixel.
    const bool at_edge = first == 0 || end == s.n - 1;
    if ((first > 0 && s.At(first - 1) >= v) || (end < s.n - 1 && s.At(end + 1) >= v)) continue;
    if (prominence < t || (at_edge && prominence == kUnjudged)) continue;
    float c;
    if (at_edge) {
      c = static_cast<float>(first == 0 ? first : end);
    } else if (end > first) {
      c = 0.5f * static_cast<float>(first + end);
    } else {
      const float l = static_cast<float>(s.At(first - 1)), r = static_cast<float>(s.At(first + 1));
      c = static_cast<float>(first) + 0.5f * (l - r) / (l - 2.0f * static_cast<float>(v) + r);
    }
    out->push_back({c, line, prominence});
  }
}

#if CV_SIMD128
// Calls add(k, before_k, after_k) for each lane k set in `mask`, with the
// lane's two falls.
template <typename Add>
void ForEachLane(unsigned mask, const cv::v_uint8x16& before, const cv::v_uint8x16& after,
                 Add add) {
  if (!mask) return;
  uchar b[kVector], a[kVector];
  cv::v_store(b, before);
  cv::v_store(a, after);
  while (mask) {
    const int k = std::countr_zero(mask);
    add(k, b[k], a[k]);
    mask &= mask - 1;
  }
}
#endif

// Appends the candidates of column x of `image` to `out`, pixel by pixel.
void ColumnCandidates(const cv::Mat& image, int x, int w, int t, std::vector<Candidate>* out) {
  const Profile p{image.ptr<uchar>(0) + x, static_cast<std::ptrdiff_t>(image.step), image.rows};
  for (int y = 0; y < image.rows; ++y) AddIfCandidate(p, y, w, t, out);
}

// The candidates of row `s` (cols pixels), in increasing order. The vector
// steps read only the row's own pixels: they cover the part where both
// windows lie inside it; the rest is judged pixel by pixel.
void RowCandidates(const uchar* s, int cols, int w, int t, std::vector<Candidate>* candidates) {
  const Profile p{s, 1, cols};
  candidates->clear();
  int x = 0;
  for (; x < std::min(w, cols); ++x) AddIfCandidate(p, x, w, t, candidates);
  const int inner_end = cols - w;  // from here the right window is cut
#if CV_SIMD128
  const cv::v_uint8x16 vt = cv::v_setall_u8(static_cast<uchar>(t));
  // The last step overlaps the one before it where the inner part is no
  // whole number of steps; its lanes done already are masked off.
  const int inner_begin = x;
  const bool vectors = inner_end - inner_begin >= kVector;
  for (int done = x; vectors && x < inner_end; x += kVector) {
    const int from = std::min(x, inner_end - kVector);
    const cv::v_uint8x16 v = cv::v_load(s + from);
    const cv::v_uint8x16 peak = (v >= cv::v_load(s + from - 1)) & (v >= cv::v_load(s + from + 1));
    if (!cv::v_check_any(peak)) {
      done = from + kVector;
      continue;
    }
    cv::v_uint8x16 left = v, right = v;
    for (int k = 1; k <= w; ++k) {
      left = cv::v_min(left, cv::v_load(s + from - k));
      right = cv::v_min(right, cv::v_load(s + from + k));
    }
    const cv::v_uint8x16 before = v - left, after = v - right;  // saturating
    unsigned mask = static_cast<unsigned>(cv::v_signmask(peak & (cv::v_min(before, after) >= vt)));
    mask &= ~0u << (done - from);  // lanes before `done` were taken by the step before
    ForEachLane(mask, before, after, [&](int k, uchar b, uchar a) {
      candidates->push_back({from + k, b, a});
    });
    done = from + kVector;
  }
  if (vectors) x = inner_end;  // the steps covered the inner part up to here
#endif
  for (; x < cols; ++x) AddIfCandidate(p, x, w, t, candidates);
}

// The candidates of columns x0 .. x0 + kVector - 1 of `image`, each
// column's in increasing row order. `rows_from` holds the start of every
// image row for rows -w - 1 .. rows + w (clamped: replication), from index 0.
void ColumnBlockCandidates(const cv::Mat& image, const std::vector<const uchar*>& rows_from, int x0,
                           int w, int t, std::vector<Candidate> (&candidates)[kVector]) {
  for (auto& c : candidates) c.clear();
  const int rows = image.rows;
#if CV_SIMD128
  auto row = [&](int y) { return rows_from[static_cast<size_t>(y + w + 1)] + x0; };
  const cv::v_uint8x16 vt = cv::v_setall_u8(static_cast<uchar>(t));
  const cv::v_uint8x16 unjudged = cv::v_setall_u8(static_cast<uchar>(kUnjudged));
  for (int y = 0; y < rows; ++y) {
    const cv::v_uint8x16 v = cv::v_load(row(y));
    const cv::v_uint8x16 peak = (v >= cv::v_load(row(y - 1))) & (v >= cv::v_load(row(y + 1)));
    if (!cv::v_check_any(peak)) continue;
    cv::v_uint8x16 above = v, below = v;
    for (int k = 1; k <= w; ++k) {
      above = cv::v_min(above, cv::v_load(row(y - k)));
      below = cv::v_min(below, cv::v_load(row(y + k)));
    }
    const cv::v_uint8x16 before = y - w < 0 ? unjudged : v - above;  // saturating
    const cv::v_uint8x16 after = y + w > rows - 1 ? unjudged : v - below;
    unsigned mask = static_cast<unsigned>(cv::v_signmask(peak & (cv::v_min(before, after) >= vt)));
    ForEachLane(mask, before, after, [&](int k, uchar b, uchar a) {
      candidates[k].push_back({y, b, a});
    });
  }
#else
  (void)rows_from;
  for (int k = 0; k < kVector; ++k) ColumnCandidates(image, x0 + k, w, t, &candidates[k]);
#endif
}

// row_start of `points`, given in order of their line (y).
void IndexLines(int lines, RidgePoints* points) {
  points->row_start.assign(static_cast<size_t>(lines) + 1, 0);
  int line = 0;
  for (size_t i = 0; i < points->points.size(); ++i)
    while (line <= points->points[i].y) points->row_start[line++] = static_cast<int>(i);
  while (line <= lines) points->row_start[line++] = static_cast<int>(points->points.size());
}

void CheckArguments(const char* who, const cv::Mat& smoothed, const RidgeParams& params) {
  if (smoothed.empty() || smoothed.type() != CV_8UC1)
    throw std::invalid_argument(std::string(who) + ": image must be a non-empty CV_8UC1 image");
  std::string why;
  if (!params.IsValid(&why)) throw std::invalid_argument(std::string(who) + ": " + why);
}

// The concatenation of `parts`.
std::vector<RidgePoint> Joined(const std::vector<std::vector<RidgePoint>>& parts) {
  size_t total = 0;
  for (const auto& f : parts) total += f.size();
  std::vector<RidgePoint> out;
  out.reserve(total);
  for (const auto& f : parts) out.insert(out.end(), f.begin(), f.end());
  return out;
}

}  // namespace

RidgePoints FindRidgePoints(const cv::Mat& smoothed, const RidgeParams& params,
                            const Cancellation& cancel) {
  CheckArguments("FindRidgePoints", smoothed, params);
  // Rows are independent: bands of them in parallel (cv::parallel_for_).
  const int bands = (smoothed.rows + kBandRows - 1) / kBandRows;
  const int w = params.half_window, t = params.min_prominence, cols = smoothed.cols;
  std::vector<std::vector<RidgePoint>> found(bands);
  BandStop stop(cancel);
  cv::parallel_for_(cv::Range(0, bands), [&](const cv::Range& r) {
    std::vector<Candidate> candidates;
    for (int b = r.start; b < r.end; ++b) {
      if (stop.Requested()) return;
      const int y1 = std::min((b + 1) * kBandRows, smoothed.rows);
      for (int y = b * kBandRows; y < y1; ++y) {
        const uchar* row = smoothed.ptr<uchar>(y);
        RowCandidates(row, cols, w, t, &candidates);
        ProfileRidgePoints({row, 1, cols}, y, candidates, t, &found[b]);
      }
    }
  });
  stop.ThrowIfStopped("the ridges along rows");
  RidgePoints out;
  out.points = Joined(found);
  IndexLines(smoothed.rows, &out);
  return out;
}

RidgePoints FindColumnRidgePoints(const cv::Mat& smoothed, const RidgeParams& params,
                                  const Cancellation& cancel) {
  CheckArguments("FindColumnRidgePoints", smoothed, params);
  // Blocks of kVector columns in parallel; the last, narrower block pixel by pixel.
  const int w = params.half_window, t = params.min_prominence;
  const int full_blocks = smoothed.cols / kVector;
  const int blocks = (smoothed.cols + kVector - 1) / kVector;
  const auto step = static_cast<std::ptrdiff_t>(smoothed.step);
  std::vector<const uchar*> rows_from;
  for (int y = -w - 1; y <= smoothed.rows + w; ++y)
    rows_from.push_back(smoothed.ptr<uchar>(std::clamp(y, 0, smoothed.rows - 1)));
  std::vector<std::vector<RidgePoint>> found(blocks);
  BandStop stop(cancel);
  cv::parallel_for_(cv::Range(0, blocks), [&](const cv::Range& r) {
    std::vector<Candidate> candidates[kVector];
    for (int b = r.start; b < r.end; ++b) {
      if (stop.Requested()) return;
      const int x0 = b * kVector;
      const int width = std::min(kVector, smoothed.cols - x0);
      if (b < full_blocks) {
        ColumnBlockCandidates(smoothed, rows_from, x0, w, t, candidates);
      } else {
        for (int k = 0; k < width; ++k) {
          candidates[k].clear();
          ColumnCandidates(smoothed, x0 + k, w, t, &candidates[k]);
        }
      }
      for (int k = 0; k < width; ++k)
        ProfileRidgePoints({smoothed.ptr<uchar>(0) + x0 + k, step, smoothed.rows}, x0 + k,
                           candidates[k], t, &found[b]);
    }
  });
  stop.ThrowIfStopped("the ridges along columns");
  RidgePoints out;
  out.points = Joined(found);
  IndexLines(smoothed.cols, &out);
  return out;
}

}  // namespace bsls::extraction
