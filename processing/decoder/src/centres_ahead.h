// Private to bsls::decoder: sub-pixel centres measured ahead, while the
// interpretation runs (docs/decoding.md, "Centres measured ahead").
//
// The interpretation (thesis 5.2) is serial and takes about a third of a
// decode; the sub-pixel stage after it measures the stripe centre across
// each labelled line's skeleton run, row by row, and across each segment's
// skeleton pixel, column by column (extraction::StripeCentreInRow /
// InColumn). Those measurements depend only on the grey frame and on the
// skeleton pixel they start from, and nearly every one of them starts from a
// pixel that extraction has already found. So, where a second core is free,
// they are measured on it from the extraction's skeleton while the first
// core interprets: every short run of a row (at most 3 px, a line's run) and
// every pixel of a short run of a column (a segment's). The sub-pixel stage
// then takes a centre from here when its key was measured and measures it
// itself otherwise (a pixel that a repair drew, a key the interpretation
// finished before), so the decode's output does not depend on how far the
// measuring ahead got: the same function of the same arguments either way.
//
// Only at the frame's own resolution (binning n = 1); a binned frame's
// skeleton is redrawn on the full frame and its keys are not known ahead.
//
// Thread-safety: Measure runs on one thread while nothing reads; after it
// has returned (and that return is synchronised with the readers, e.g. by a
// future), InRow / InColumn may be called from any number of threads.
#ifndef BSLS_DECODER_SRC_CENTRES_AHEAD_H_
#define BSLS_DECODER_SRC_CENTRES_AHEAD_H_

#include <atomic>
#include <opencv2/core.hpp>
#include <optional>
#include <utility>
#include <vector>

#include "bsls/extraction/stripe_centre.h"

namespace bsls::decoder::internal {

class CentresAhead {
 public:
  // Nothing planned: every look-up measures.
  CentresAhead() = default;

  // Plans the keys from `skeleton` (CV_8UC1, non-zero set), found on the part
  // of the full frame from `offset` on, at the frame's own resolution.
  CentresAhead(const cv::Mat& skeleton, cv::Point offset);

  // Measures the planned keys on `grey` (the full frame, CV_8UC1), rows
  // first, until all are done or `stop` is set; returns how many it measured.
  int Measure(const cv::Mat& grey, const extraction::StripeCentreParams& params,
              const std::atomic<bool>& stop);

  // extraction::StripeCentreInRow(grey, y, x, params), from here when it was
  // measured ahead with the same grey and params.
  std::optional<double> InRow(const cv::Mat& grey, int y, double x,
                              const extraction::StripeCentreParams& params) const;

  // extraction::StripeCentreInColumn(grey, x, y, params), likewise.
  std::optional<double> InColumn(const cv::Mat& grey, int x, int y,
                                 const extraction::StripeCentreParams& params) const;

 private:
  // Sorted keys, each with its centre once measured.
  struct Table {
    std::vector<std::pair<int, int>> keys;
    std::vector<std::optional<double>> centres;
    std::vector<char> done;
    // The entry of `key`, or nullptr where it was not measured.
    const std::optional<double>* Find(std::pair<int, int> key) const;
  };

  Table rows_;     // (y, 2 x): a row's run with its middle at x
  Table columns_;  // (x, y)
};

}  // namespace bsls::decoder::internal

#endif  // BSLS_DECODER_SRC_CENTRES_AHEAD_H_
