#include "working_resolution.h"

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>
#include <vector>

namespace bsls::decoder::internal {
namespace {

// A reduction within this fraction of a whole factor is made by that factor.
constexpr double kWholeFactorSpread = 0.1;

// The full-frame pixel at the centre of binned pixel p (n odd: exact; n even:
// the one just above and left of the centre).
cv::Point Centre(const cv::Point& p, int n) {
  return {n * p.x + (n - 1) / 2, n * p.y + (n - 1) / 2};
}

// Appends the pixels of the straight 8-connected run from a to b, a left out.
void AppendRun(const cv::Point& a, const cv::Point& b, std::vector<cv::Point>* out) {
  cv::LineIterator it(a, b, 8);
  ++it;  // a itself
  for (int i = 1; i < it.count; ++i, ++it) out->push_back(it.pos());
}

// The pixels of a binned pixel set redrawn on the full frame: each pixel's
// centre, joined by a straight run to each of its 8-neighbours in the set.
// `set` is a binned-size CV_8UC1 image, non-zero on the set.
std::vector<cv::Point> RedrawSet(const std::vector<cv::Point>& pixels, const cv::Mat& set, int n) {
  std::vector<cv::Point> out;
  out.reserve(pixels.size() * static_cast<size_t>(n) * 2);
  const cv::Rect inside(0, 0, set.cols, set.rows);
  for (const cv::Point& p : pixels) {
    const cv::Point c = Centre(p, n);
    out.push_back(c);
    // Each neighbour pair once: the neighbours after p in row-major order.
    for (const cv::Point d :
         {cv::Point(1, 0), cv::Point(-1, 1), cv::Point(0, 1), cv::Point(1, 1)}) {
      const cv::Point q = p + d;
      if (inside.contains(q) && set.at<uchar>(q)) AppendRun(c, Centre(q, n), &out);
    }
  }
  std::sort(out.begin(), out.end(), [](const cv::Point& a, const cv::Point& b) {
    return a.y != b.y ? a.y < b.y : a.x < b.x;
  });
  out.erase(std::unique(out.begin(), out.end()), out.end());
  return out;
}

}  // namespace

int BinningFor(double pitch, double tuned_pitch, const DecodeParams& params) {
  if (params.binning > 0) return params.binning;
  if (pitch <= 0.0) return 1;
  return std::clamp(static_cast<int>(std::lround(pitch / tuned_pitch)), 1, params.max_binning);
}

double WorkingFactor(double pitch, const DecodeParams& params) {
  const TrackChainParams& tp = params.track_chain;
  if (params.binning > 0) return params.binning;
  if (!(pitch > 0.0) || (pitch >= tp.native_pitch_min && pitch <= tp.native_pitch_max)) return 1.0;
  const double factor =
      std::clamp(pitch / tp.tuned_pitch, tp.min_scale, static_cast<double>(params.max_binning));
  // Near a whole factor, the whole one: exact block means, as a sensor bins.
  const double whole = std::round(factor);
  return whole >= 2.0 && std::abs(factor - whole) <= kWholeFactorSpread * whole ? whole : factor;
}

WorkingScale ResampleFrame(const cv::Mat& grey, double factor, cv::Mat* working) {
  if (factor == 1.0) {
    *working = grey;
    return {};
  }
  const cv::Size size(std::max(1, static_cast<int>(std::lround(grey.cols / factor))),
                      std::max(1, static_cast<int>(std::lround(grey.rows / factor))));
  cv::resize(grey, *working, size, 0, 0, factor > 1.0 ? cv::INTER_AREA : cv::INTER_CUBIC);
  return {static_cast<double>(grey.cols) / size.width,
          static_cast<double>(grey.rows) / size.height};
}

cv::Mat BinFrame(const cv::Mat& grey, int n) {
  if (n <= 1) return grey;
  const cv::Size binned(grey.cols / n, grey.rows / n);
  cv::Mat out;
  // INTER_AREA at an integer factor is exactly the block mean, rounded.
  cv::resize(grey(cv::Rect(0, 0, binned.width * n, binned.height * n)), out, binned, 0, 0,
             cv::INTER_AREA);
  return out;
}

GreyHistogram::GreyHistogram(const cv::Mat& grey) : total_(static_cast<double>(grey.total())) {
  // Four tallies taken in turn, so that runs of one level (the dark ground)
  // do not wait on one counter; summed at the end.
  int tally[4][256] = {};
  for (int y = 0; y < grey.rows; ++y) {
    const uchar* row = grey.ptr<uchar>(y);
    int x = 0;
    for (; x + 4 <= grey.cols; x += 4) {
      ++tally[0][row[x]];
      ++tally[1][row[x + 1]];
      ++tally[2][row[x + 2]];
      ++tally[3][row[x + 3]];
    }
    for (; x < grey.cols; ++x) ++tally[0][row[x]];
  }
  for (int i = 0; i < 256; ++i) count_[i] = tally[0][i] + tally[1][i] + tally[2][i] + tally[3][i];
}

int GreyHistogram::Percentile(double fraction) const {
  double seen = 0;
  for (int i = 0; i < 256; ++i) {
    seen += count_[i];
    if (seen >= fraction * total_) return i;
  }
  return 255;
}

double GreyHistogram::ShareFrom(int level) const {
  double above = 0;
  for (int i = std::max(level, 0); i < 256; ++i) above += count_[i];
  return above / total_;
}

cv::Rect PatternColumns(const cv::Mat& grey, int n, double rise, int margin) {
  const cv::Rect whole(0, 0, grey.cols, grey.rows);
  constexpr int kBlock = 4;
  if (!(rise > 0.0) || grey.cols < 2 * kBlock || grey.rows < kBlock) return whole;
  cv::Mat means;
  const cv::Size blocks(grey.cols / kBlock, grey.rows / kBlock);
  // INTER_AREA at an integer factor is exactly the block mean.
  cv::resize(grey(cv::Rect(0, 0, blocks.width * kBlock, blocks.height * kBlock)), means, blocks, 0,
             0, cv::INTER_AREA);
  // The dark ground: the 5th percentile of the block means.
  const double above = GreyHistogram(means).Percentile(0.05) + rise;
  int first = means.cols, last = -1;
  for (int y = 0; y < means.rows; ++y) {
    const uchar* m = means.ptr<uchar>(y);
    for (int x = 0; x < means.cols; ++x)
      if (m[x] > above) {
        first = std::min(first, x);
        last = std::max(last, x);
      }
  }
  if (last < 0) return whole;
  int left = std::max(0, first * kBlock - margin);
  left -= left % std::max(n, 1);
  const int right = std::min(grey.cols, (last + 1) * kBlock + margin);
  return {left, 0, right - left, grey.rows};
}

cv::Point2d ToFullFrame(const cv::Point2d& p, int n) {
  return WorkingScale{static_cast<double>(n), static_cast<double>(n)}.ToFull(p);
}

void MapToFullFrame(int n, cv::Point offset, cv::Size full,
                    interpretation::InterpretationResult* r) {
  auto shift = [offset](std::vector<cv::Point>* pixels) {
    for (cv::Point& p : *pixels) p += offset;
  };
  if (n <= 1) {  // the same pixels, moved by `offset`
    if (offset == cv::Point() && r->skeleton.size() == full) return;
    cv::Mat skeleton = cv::Mat::zeros(full, CV_8UC1);
    r->skeleton.copyTo(skeleton(cv::Rect(offset, r->skeleton.size())));
    r->skeleton = skeleton;
    for (interpretation::LabelledLine& line : r->labelling.lines) shift(&line.pixels);
    for (interpretation::LabelledJunction& j : r->labelling.junctions) {
      j.position += cv::Point2d(offset);
      shift(&j.segment);
    }
    return;
  }
  const cv::Mat& binned = r->skeleton;
  // The skeleton.
  std::vector<cv::Point> pixels;
  cv::findNonZero(binned, pixels);
  cv::Mat skeleton = cv::Mat::zeros(full, CV_8UC1);
  for (const cv::Point& p : RedrawSet(pixels, binned, n)) skeleton.at<uchar>(p + offset) = 255;
  // Labelled lines: their own pixels only, so that a line does not take in
  // the segments that leave it.
  cv::Mat own = cv::Mat::zeros(binned.size(), CV_8UC1);
  for (interpretation::LabelledLine& line : r->labelling.lines) {
    for (const cv::Point& p : line.pixels) own.at<uchar>(p) = 1;
    std::vector<cv::Point> redrawn = RedrawSet(line.pixels, own, n);
    for (const cv::Point& p : line.pixels) own.at<uchar>(p) = 0;
    line.pixels = std::move(redrawn);
    shift(&line.pixels);
  }
  // Junctions: positions, and segments in their order (from the junction on).
  for (interpretation::LabelledJunction& j : r->labelling.junctions) {
    j.position = ToFullFrame(j.position, n) + cv::Point2d(offset);
    if (j.segment.empty()) continue;
    std::vector<cv::Point> segment{Centre(j.segment.front(), n)};
    for (size_t i = 1; i < j.segment.size(); ++i)
      AppendRun(Centre(j.segment[i - 1], n), Centre(j.segment[i], n), &segment);
    j.segment = std::move(segment);
    shift(&j.segment);
  }
  r->skeleton = skeleton;
}

}  // namespace bsls::decoder::internal
