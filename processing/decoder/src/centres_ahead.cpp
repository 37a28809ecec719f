#include "centres_ahead.h"

#include <algorithm>
#include <cassert>
#include <cmath>

namespace bsls::decoder::internal {
namespace {

// The longest run (px) of a row or column that is measured ahead: a line's
// run in a row at the frame's resolution is at most 3 px (decoder.cpp,
// MeasureLine: hi - lo <= 2 n); a segment crosses a column in 1-3 px.
constexpr int kLongestRun = 3;

// A row is not measured ahead where the skeleton passes kBesideFrom ..
// kBesideTo columns beside its run within kBesideRows rows (decoder.cpp,
// SegmentNearby: 2-4 columns, junction_clearance = 3 rows).
constexpr int kBesideFrom = 2, kBesideTo = 4, kBesideRows = 3;

// Calls run(along, from, to) for every run of set pixels of `skeleton` along
// its rows (by_rows) or columns, at most kLongestRun long.
template <typename Run>
void ForEachShortRun(const cv::Mat& skeleton, bool by_rows, Run run) {
  const int lines = by_rows ? skeleton.rows : skeleton.cols;
  const int length = by_rows ? skeleton.cols : skeleton.rows;
  auto set = [&](int along, int i) {
    return by_rows ? skeleton.at<uchar>(along, i) != 0 : skeleton.at<uchar>(i, along) != 0;
  };
  for (int along = 0; along < lines; ++along) {
    for (int i = 0; i < length;) {
      if (!set(along, i)) {
        ++i;
        continue;
      }
      int j = i;
      while (j + 1 < length && set(along, j + 1)) ++j;
      if (j - i + 1 <= kLongestRun) run(along, i, j);
      i = j + 1;
    }
  }
}

}  // namespace

const std::optional<double>* CentresAhead::Table::Find(std::pair<int, int> key) const {
  const auto it = std::lower_bound(keys.begin(), keys.end(), key);
  if (it == keys.end() || *it != key) return nullptr;
  const size_t i = static_cast<size_t>(it - keys.begin());
  return done[i] ? &centres[i] : nullptr;
}

CentresAhead::CentresAhead(const cv::Mat& skeleton, cv::Point offset) {
  CV_Assert(skeleton.type() == CV_8UC1);
  auto set = [&](int x, int y) {
    return x >= 0 && y >= 0 && x < skeleton.cols && y < skeleton.rows &&
           skeleton.at<uchar>(y, x) != 0;
  };
  // Whether a set pixel lies kBesideFrom .. kBesideTo columns to either side
  // of from .. to within kBesideRows rows of y: a segment leaving there or a
  // line crowding, where the sub-pixel stage does not measure the row alone.
  auto beside = [&](int y, int from, int to) {
    for (int dy = -kBesideRows; dy <= kBesideRows; ++dy)
      for (int d = kBesideFrom; d <= kBesideTo; ++d)
        if (set(from - d, y + dy) || set(to + d, y + dy)) return true;
    return false;
  };
  // Rows: the middle of each short run, as twice its x (an integer).
  ForEachShortRun(skeleton, true, [&](int y, int from, int to) {
    if (!beside(y, from, to)) rows_.keys.emplace_back(y + offset.y, from + to + 2 * offset.x);
  });
  // Columns: every pixel of each short run that runs sideways in its row (a
  // segment's; a line's pixel stands alone in its row).
  ForEachShortRun(skeleton, false, [&](int x, int from, int to) {
    for (int y = from; y <= to; ++y)
      if (set(x - 1, y) || set(x + 1, y)) columns_.keys.emplace_back(x + offset.x, y + offset.y);
  });
  for (Table* t : {&rows_, &columns_}) {
    // Both come sorted, as Find needs: runs are walked line by line, and
    // along each line in order.
    assert(std::is_sorted(t->keys.begin(), t->keys.end()));
    t->centres.assign(t->keys.size(), std::nullopt);
    t->done.assign(t->keys.size(), 0);
  }
}

int CentresAhead::Measure(const cv::Mat& grey, const extraction::StripeCentreParams& params,
                          const std::atomic<bool>& stop) {
  int measured = 0;
  for (Table* t : {&rows_, &columns_}) {
    const bool by_rows = t == &rows_;
    for (size_t i = 0; i < t->keys.size(); ++i) {
      if (stop.load(std::memory_order_relaxed)) return measured;
      const auto [a, b] = t->keys[i];
      t->centres[i] = by_rows ? extraction::StripeCentreInRow(grey, a, 0.5 * b, params)
                              : extraction::StripeCentreInColumn(grey, a, b, params);
      t->done[i] = 1;
      ++measured;
    }
  }
  return measured;
}

std::optional<double> CentresAhead::InRow(const cv::Mat& grey, int y, double x,
                                          const extraction::StripeCentreParams& params) const {
  const double twice = 2.0 * x;
  if (twice == std::floor(twice) && std::abs(twice) < 1e9)
    if (const auto* found = rows_.Find({y, static_cast<int>(twice)})) return *found;
  return extraction::StripeCentreInRow(grey, y, x, params);
}

std::optional<double> CentresAhead::InColumn(const cv::Mat& grey, int x, int y,
                                             const extraction::StripeCentreParams& params) const {
  if (const auto* found = columns_.Find({x, y})) return *found;
  return extraction::StripeCentreInColumn(grey, x, y, params);
}

}  // namespace bsls::decoder::internal
