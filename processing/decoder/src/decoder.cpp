#include "bsls/decoder/decoder.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <future>
#include <limits>
#include <map>
#include <opencv2/imgproc.hpp>
#include <optional>
#include <stdexcept>

#include "bsls/geometry/curve_fit.h"
#include "centres_ahead.h"
#include "junction_placement.h"
#include "track_chain.h"
#include "working_resolution.h"

namespace bsls::decoder {
namespace {

using geometry::FitAtZero;
using geometry::FitLine;
using geometry::FitParabola;
using geometry::Quadratic;

using Clock = std::chrono::steady_clock;

double MsSince(Clock::time_point t) {
  return std::chrono::duration<double, std::milli>(Clock::now() - t).count();
}

// Says why a frame cannot carry the pattern, or returns an empty string.
std::string CheckFrame(const cv::Mat& grey, const DecodeParams& params) {
  const internal::GreyHistogram levels(grey);
  const int lo = levels.Percentile(0.01), hi = levels.Percentile(0.99);
  const double saturated = levels.ShareFrom(254);
  if (saturated > params.max_saturated_fraction)
    return "frame is saturated (" + std::to_string(static_cast<int>(saturated * 100)) +
           "% of pixels at full scale)";
  if (hi - lo < params.min_dynamic_range &&
      levels.Percentile(0.999) - lo < params.min_dynamic_range)
    return "frame is blank (grey levels " + std::to_string(lo) + ".." + std::to_string(hi) +
           " hold 98% of pixels)";
  return {};
}

// The parabola's value at t = 0 (FitParabola) where its RMS residual over the
// samples is at most max_rms; nullopt otherwise (also for max_rms <= 0).
std::optional<double> CloseParabolaAtZero(const std::vector<std::pair<double, double>>& s,
                                          double max_rms) {
  Quadratic c;
  if (!(max_rms > 0.0) || !FitParabola(s, &c)) return std::nullopt;
  double squares = 0.0;
  for (const auto& [t, x] : s) {
    const double e = x - (c[0] + c[1] * t + c[2] * t * t);
    squares += e * e;
  }
  if (std::sqrt(squares / static_cast<double>(s.size())) > max_rms) return std::nullopt;
  return c[0];
}

// Values by image row over a range of rows, each row holding one value or
// none (a line's rows: dense, so look-ups need no search).
class RowValues {
 public:
  // Rows first .. first + count - 1, all empty.
  void Reset(int first, int count) {
    first_ = first;
    values_.assign(static_cast<size_t>(std::max(count, 0)), kEmpty);
  }
  int First() const { return first_; }
  int End() const { return first_ + static_cast<int>(values_.size()); }  // one past the last row
  bool Has(int y) const { return y >= first_ && y < End() && !std::isnan(values_[Slot(y)]); }
  double At(int y) const { return values_[Slot(y)]; }  // Has(y) must hold
  void Set(int y, double v) { values_[Slot(y)] = v; }  // y within the range
  void Erase(int y) { values_[Slot(y)] = kEmpty; }

 private:
  static constexpr double kEmpty = std::numeric_limits<double>::quiet_NaN();
  size_t Slot(int y) const { return static_cast<size_t>(y - first_); }

  int first_ = 0;
  std::vector<double> values_;
};

// The rows of `rows` within `radius` of `centre` and farther than `exclude`
// from it, in order, as (row - centre, x) pairs for the fits above.
std::vector<std::pair<double, double>> RowsNear(const RowValues& rows, double centre, int radius,
                                                double exclude) {
  std::vector<std::pair<double, double>> out;
  out.reserve(static_cast<size_t>(2 * radius + 2));  // one allocation, not one per doubling
  const int from = std::max(rows.First(), cvFloor(centre) - radius);
  for (int y = from; y < rows.End() && y <= centre + radius; ++y)
    if (rows.Has(y) && std::abs(y - centre) > exclude) out.push_back({y - centre, rows.At(y)});
  return out;
}

// A labelled line's skeleton pixels as the sub-pixel stage reads them: as
// sorted (x, y) for look-ups, and each row's run (min x, max x) from row
// `top` on (min > max where the line has no pixel in the row).
struct LinePixels {
  std::vector<std::pair<int, int>> sorted;
  int top = 0;
  std::vector<std::pair<int, int>> runs;

  // Whether (x, y) is a pixel of the line.
  bool Has(int x, int y) const {
    return std::binary_search(sorted.begin(), sorted.end(), std::make_pair(x, y));
  }
};

// `line`'s pixels as LinePixels.
LinePixels PrepareLine(const interpretation::LabelledLine& line) {
  LinePixels out;
  out.sorted.reserve(line.pixels.size());
  for (const cv::Point& q : line.pixels) out.sorted.emplace_back(q.x, q.y);
  std::sort(out.sorted.begin(), out.sorted.end());
  if (out.sorted.empty()) return out;
  int bottom = out.top = out.sorted.front().second;
  for (const auto& [x, y] : out.sorted) {
    out.top = std::min(out.top, y);
    bottom = std::max(bottom, y);
  }
  out.runs.assign(static_cast<size_t>(bottom - out.top + 1),
                  {std::numeric_limits<int>::max(), std::numeric_limits<int>::min()});
  for (const auto& [x, y] : out.sorted) {
    auto& [lo, hi] = out.runs[static_cast<size_t>(y - out.top)];
    lo = std::min(lo, x);
    hi = std::max(hi, x);
  }
  return out;
}

// Thesis 5.1.4.8, measured: the rows where labelled lines crowd (folds
// that turn the face away squeeze neighbouring lines to a few pixels), each
// row's crowd fitted once, jointly (extraction::StripeCentresInRow), so
// that a line's centre there is not pulled by its neighbours' light.
struct CrowdedRows {
  struct Row {
    std::vector<int> p;                    // the crowding lines, left to right
    std::vector<std::optional<double>> x;  // their centres (nullopt: no proper ridge)
    bool Has(int line) const { return std::find(p.begin(), p.end(), line) != p.end(); }
    // The joint fit's centre of `line` (a member), nullopt where it failed.
    std::optional<double> At(int line) const {
      return x[static_cast<size_t>(std::find(p.begin(), p.end(), line) - p.begin())];
    }
  };
  std::map<int, std::vector<Row>> rows;     // image row -> its crowds
  std::map<int, const LinePixels*> pixels;  // p -> the pixels of every line in a crowd

  // Whether (x, y) is a pixel of a line of `crowd`.
  bool OnLineOf(const Row& crowd, int x, int y) const {
    for (int p : crowd.p)
      if (pixels.at(p)->Has(x, y)) return true;
    return false;
  }

  // The crowd of line `p` in row y; nullptr where the line is alone.
  const Row* Find(int y, int p) const {
    const auto it = rows.find(y);
    if (it == rows.end()) return nullptr;
    for (const Row& row : it->second)
      if (row.Has(p)) return &row;
    return nullptr;
  }
};

// Every row where the skeletons of two or more labelled lines pass within
// crowd_distance of each other (each line's skeleton a narrow run there:
// at most 2n px), grouped into chains of neighbours and fitted jointly.
CrowdedRows MeasureCrowdedRows(const cv::Mat& grey,
                               const std::vector<interpretation::LabelledLine>& lines,
                               const std::vector<LinePixels>& pixels, const DecodeParams& params,
                               int n) {
  // x_of[y * L + i]: the middle of line i's skeleton run in row y (NaN: none).
  const size_t count = lines.size();
  std::vector<double> x_of(static_cast<size_t>(grey.rows) * count,
                           std::numeric_limits<double>::quiet_NaN());
  for (size_t i = 0; i < count; ++i) {
    const LinePixels& line = pixels[i];
    for (size_t k = 0; k < line.runs.size(); ++k) {
      const auto [lo, hi] = line.runs[k];
      if (hi >= lo && hi - lo <= 2 * n)
        x_of[static_cast<size_t>(line.top + static_cast<int>(k)) * count + i] = 0.5 * (lo + hi);
    }
  }
  struct Crowd {
    int y;
    CrowdedRows::Row row;
    std::vector<double> guess;  // the skeleton x of each member
  };
  std::vector<Crowd> crowds;
  std::vector<std::pair<double, int>> found;  // (x, index of the line) in one row
  for (int y = 0; y < grey.rows; ++y) {
    found.clear();
    for (size_t i = 0; i < count; ++i)
      if (const double x = x_of[static_cast<size_t>(y) * count + i]; !std::isnan(x))
        found.emplace_back(x, static_cast<int>(i));
    std::sort(found.begin(), found.end());
    for (size_t i = 0; i < found.size();) {
      size_t j = i + 1;
      while (j < found.size() && found[j].first - found[j - 1].first <= params.crowd_distance) ++j;
      if (j - i >= 2) {
        Crowd crowd{y, {}, {}};
        for (size_t k = i; k < j; ++k) {
          crowd.row.p.push_back(lines[static_cast<size_t>(found[k].second)].p);
          crowd.guess.push_back(found[k].first);
        }
        crowds.push_back(std::move(crowd));
      }
      i = j;
    }
  }
  auto fit = [&](const cv::Range& r) {
    for (int i = r.start; i < r.end; ++i) {
      Crowd& c = crowds[static_cast<size_t>(i)];
      c.row.x = extraction::StripeCentresInRow(grey, c.y, c.guess, params.centre);
    }
  };
  // A face has a handful of crowded rows: waking the thread pool for them
  // costs more than the fits.
  constexpr int kParallelFrom = 16;
  const cv::Range all(0, static_cast<int>(crowds.size()));
  if (all.end >= kParallelFrom)
    cv::parallel_for_(all, fit);
  else
    fit(all);
  CrowdedRows out;
  for (Crowd& c : crowds) out.rows[c.y].push_back(std::move(c.row));
  for (size_t i = 0; i < count; ++i) out.pixels[lines[i].p] = &pixels[i];
  return out;
}

struct LineCentres {
  RowValues measured;  // row -> sub-pixel x, outliers removed
  // The measured rows that no segment passes within its widened clearance:
  // the junction fits use only these.
  RowValues clear;
  RowValues skeleton;         // row -> mean x of the line's skeleton pixels
  RowValues slope;            // row -> |dx/dy| of the skeleton there (rows the skeleton crosses)
  std::vector<char> skipped;  // by row from measured.First(): crossed but not measured
  std::vector<cv::Point2d> points;  // the decoded centres: measured, skipped rows refilled
};

// How near a segment leaving the line passes a row of it.
enum class SegmentNear {
  kNone,    // none within the widened clearance
  kObtuse,  // only beyond the base clearance, where the line leans away from it
  kNear,    // within the base clearance, or where the line runs along it
};

// Whether the skeleton has a segment leaving the line near (x, y): set pixels
// 2-4 columns to either side that are not part of the line itself nor of a
// line crowding it in row y (`crowd` of `crowded`, measured with it), within
// `clearance` rows, or within `wide_clearance` rows on the side of the
// segment where a line leaning at `slope` (dx/dy) runs along it (the acute
// angle between them; there a steep line's wide row profile takes in the
// segment's light over many rows) or away from it.
SegmentNear SegmentNearby(const cv::Mat& skeleton, const LinePixels& own,
                          const CrowdedRows& crowded, const CrowdedRows::Row* crowd, int x, int y,
                          int clearance, int wide_clearance, double slope) {
  const int reach = std::max(clearance, wide_clearance);
  SegmentNear out = SegmentNear::kNone;
  for (int dy = -reach; dy <= reach; ++dy) {
    const int yy = y + dy;
    if (yy < 0 || yy >= skeleton.rows) continue;
    const uchar* row = skeleton.ptr<uchar>(yy);
    for (int k = 2; k <= 4; ++k)
      for (int side : {-1, 1}) {
        const int xx = x + side * k;
        if (xx < 0 || xx >= skeleton.cols || !row[xx] || own.Has(xx, yy) ||
            (crowd && crowded.OnLineOf(*crowd, xx, yy)))
          continue;
        if (std::abs(dy) <= clearance || dy * slope * side < 0) return SegmentNear::kNear;
        out = SegmentNear::kObtuse;
      }
  }
  return out;
}

// dx/dy of a line's skeleton over `reach` rows each side of row y (0 when unknown).
double LocalSlope(const RowValues& skeleton, int y, int reach) {
  int a = y - reach, last = y + reach;
  while (a <= y + reach && !skeleton.Has(a)) ++a;
  while (last >= a && !skeleton.Has(last)) --last;
  if (a > y + reach || last <= a) return 0.0;
  return (skeleton.At(last) - skeleton.At(a)) / (last - a);
}

// Sub-pixel centres of one labelled line, one per row its skeleton crosses.
// Rows beside a segment are skipped (the segment's light biases them), and a
// centre far from the fit of its neighbours is dropped as an outlier; skipped
// rows are refilled from the fit of their neighbours where the line is not
// steep and measured rows lie on both sides. `params` holds the lengths of
// the full frame (ScaledForBinning); `n` is the binning the skeleton was
// found at: the skeleton's own pixel sizes (a row's run, the slope's reach)
// are n times larger.
LineCentres MeasureLine(const cv::Mat& grey, const cv::Mat& skeleton, int p, const LinePixels& own,
                        const CrowdedRows& crowded, const internal::CentresAhead& ahead,
                        const DecodeParams& params, int n) {
  LineCentres out;
  const int first = own.top;
  const int count = static_cast<int>(own.runs.size());
  out.measured.Reset(first, count);
  out.clear.Reset(first, count);
  out.skeleton.Reset(first, count);
  out.slope.Reset(first, count);
  out.skipped.assign(static_cast<size_t>(count), 0);
  auto skip = [&](int y) { out.skipped[static_cast<size_t>(y - first)] = 1; };
  for (int y = first; y < first + count; ++y) {
    const auto [lo, hi] = own.runs[static_cast<size_t>(y - first)];
    if (hi >= lo && hi - lo <= 2 * n) out.skeleton.Set(y, 0.5 * (lo + hi));
  }
  for (int y = first; y < first + count; ++y) {
    const auto [lo, hi] = own.runs[static_cast<size_t>(y - first)];
    if (hi < lo) continue;  // no pixel of the line in this row
    // A steep line's row profile is wide, so a segment biases more rows of it
    // on the side where the line runs along it.
    const double signed_slope = LocalSlope(out.skeleton, y, 3 * n);
    const double slope = std::abs(signed_slope);
    out.slope.Set(y, slope);
    const int clearance =
        params.junction_clearance +
        static_cast<int>(std::lround(2.0 * params.junction_clearance *
                                     std::max(0.0, slope - params.max_fill_slope)));
    const int x = (lo + hi) / 2;
    // Where the joint fit of its crowd failed, the line is measured on its
    // own, as if it were alone.
    const CrowdedRows::Row* crowd = crowded.Find(y, p);
    const std::optional<double> joint = crowd ? crowd->At(p) : std::nullopt;
    if (!joint) crowd = nullptr;
    // A row where the skeleton runs sideways is a segment, not the line.
    const SegmentNear near =
        hi - lo > 2 * n ? SegmentNear::kNear
                        : SegmentNearby(skeleton, own, crowded, crowd, x, y,
                                        params.junction_clearance, clearance, signed_slope);
    if (near == SegmentNear::kNear) {
      skip(y);
      continue;
    }
    if (auto cx = joint ? joint : ahead.InRow(grey, y, 0.5 * (lo + hi), params.centre)) {
      out.measured.Set(y, *cx);
      if (near == SegmentNear::kNone) out.clear.Set(y, *cx);
    } else {
      skip(y);
    }
  }
  // Outliers: more than max_centre_residual from the line through the
  // neighbours within junction_fit_rows on the same stretch of the line: not
  // across two or more rows skipped beside a segment, where a line may fold
  // (nose, lips) and the far side's centres are no guide.
  auto skipped_at = [&](int y) { return out.skipped[static_cast<size_t>(y - first)] != 0; };
  auto stretch_end = [&](int y, int step) {  // last row of y's stretch towards step
    int end = y;
    for (int k = y + step;
         k >= first && k < first + count && std::abs(k - y) <= params.junction_fit_rows;
         k += step) {
      if (skipped_at(k) && k + step >= first && k + step < first + count && skipped_at(k + step))
        break;
      end = k;
    }
    return end;
  };
  std::vector<int> outliers;
  for (int y = first; y < first + count; ++y) {
    if (!out.measured.Has(y)) continue;
    auto s = RowsNear(out.measured, y, params.junction_fit_rows, 0.0);
    const double lo = stretch_end(y, -1) - y, hi = stretch_end(y, +1) - y;
    std::erase_if(s, [&](const auto& r) { return r.first < lo || r.first > hi; });
    if (s.size() < 4) continue;
    const auto fit = FitAtZero(s);
    if (fit && std::abs(out.measured.At(y) - *fit) > params.max_centre_residual)
      outliers.push_back(y);
  }
  for (int y : outliers) {
    out.measured.Erase(y);
    out.clear.Erase(y);
    skip(y);
  }
  // The decoded points: measured centres, and the skipped rows filled from
  // the line's own fit where measured rows lie on both sides.
  for (int y = first; y < first + count; ++y) {
    if (out.measured.Has(y)) {
      out.points.emplace_back(out.measured.At(y), y);
      continue;
    }
    if (!out.skipped[static_cast<size_t>(y - first)]) continue;
    const auto s = RowsNear(out.measured, y, params.junction_fit_rows, 0.0);
    const auto above = std::count_if(s.begin(), s.end(), [](const auto& r) { return r.first < 0; });
    const auto below = std::count_if(s.begin(), s.end(), [](const auto& r) { return r.first > 0; });
    if (above == 0 || below == 0 || s.size() < 4) continue;
    if (!(out.slope.Has(y) && out.slope.At(y) > params.max_fill_slope)) {
      if (const auto fit = FitAtZero(s)) out.points.emplace_back(*fit, y);
      continue;
    }
    // A steep stretch's fit is good enough only where it holds its measured
    // rows closely, with two of them on each side at least.
    if (above < 2 || below < 2) continue;
    if (const auto fit = CloseParabolaAtZero(s, params.steep_fill_residual))
      out.points.emplace_back(*fit, y);
  }
  return out;
}

// The first step of RefineJunction: the line's fit and the segment columns
// to measure (the segment's ends skipped, where the lines' light biases it).
internal::JunctionPlan PlanJunction(const LineCentres& line,
                                    const interpretation::LabelledJunction& j,
                                    const DecodeParams& params, int n_binning) {
  const double y0 = j.position.y;
  internal::JunctionPlan plan;
  // The line as x(y): sub-pixel centres, or where a steep or crowded line has
  // too few of them, its skeleton (within a pixel of the centre).
  plan.vertical = RowsNear(line.clear, y0, params.junction_fit_rows, 0.0);
  if (plan.vertical.size() >= 3 && FitLine(plan.vertical, &plan.a, &plan.b)) {
    plan.wide = RowsNear(line.clear, y0, 2 * params.junction_fit_rows, 0.0);
  } else {
    // The skeleton bends into the segment within junction_clearance of the
    // junction (most where a steep line meets it at a sharp angle): those
    // rows are left out while enough others remain.
    plan.vertical = RowsNear(line.skeleton, y0, params.junction_fit_rows,
                             static_cast<double>(params.junction_clearance));
    if (plan.vertical.size() < 3 || !FitLine(plan.vertical, &plan.a, &plan.b))
      plan.vertical = RowsNear(line.skeleton, y0, params.junction_fit_rows, 1.0 * n_binning);
    if (plan.vertical.size() < 3 || !FitLine(plan.vertical, &plan.a, &plan.b)) return plan;
  }
  plan.ok = true;
  if (j.interpolated || j.segment.empty()) return plan;
  const int n = static_cast<int>(j.segment.size());
  for (int i = 0;
       i < n - 2 * n_binning && static_cast<int>(plan.columns.size()) < params.segment_fit_columns;
       ++i) {
    const cv::Point& s = j.segment[i];
    // Where the segment's skeleton turns into a line (its far end unlit,
    // the chain goes on along the neighbour line's lit stretch) its columns
    // end: beyond, they measure that line. (Not before the first column:
    // next to the junction the skeleton may bend into the line.)
    if (!plan.columns.empty() && i >= 3 * n_binning) {
      const cv::Point back = j.segment[i - 3 * n_binning];
      if (std::abs(s.y - back.y) > std::abs(s.x - back.x)) break;
    }
    if (std::abs(s.x - plan.a) <= params.junction_clearance) continue;
    plan.columns.push_back(s);
  }
  return plan;
}

// The sub-pixel stage's lengths for a frame binned n x n for extraction and
// interpretation: every pixel length of the centres and the junction fits
// multiplied by n, so that they span the same part of the pattern as at the
// working resolution (the averaging along a stripe capped at its largest
// radius, 4).
DecodeParams ScaledForBinning(const DecodeParams& params, int n) {
  DecodeParams out = params;
  if (n <= 1) return out;
  out.junction_fit_rows *= n;
  out.segment_fit_columns *= n;
  out.junction_clearance *= n;
  out.max_centre_residual *= n;
  out.steep_fill_residual *= n;
  out.fold_tip_spread *= n;
  out.crowd_distance *= n;
  out.centre.search_radius *= n;
  out.centre.max_width *= n;
  out.centre.min_sigma *= n;
  out.centre.along_radius = std::min(4, out.centre.along_radius * n);
  return out;
}

// The skeleton chain's features at its working resolution.
struct WorkingFeatures {
  int n = 1;        // the frame binned n x n
  cv::Rect region;  // the part of the frame binned: the pattern's columns
  extraction::ExtractionResult features;
};

// The working resolution: the frame binned so that its stripe pitch is
// near the one the pixel-sized parameters are tuned for, cropped to the
// pattern's columns, and its features extracted. Sets result's pitch
// (measured unless params.binning fixes the binning), binning, region and
// extraction time.
WorkingFeatures ExtractWorkingFeatures(const cv::Mat& grey, const DecodeParams& params,
                                       const Cancellation& cancel, DecodeResult* result) {
  const auto t = Clock::now();
  if (params.binning == 0)
    result->pitch = extraction::MeasureStripePitch(grey, params.pitch).value_or(0.0);
  cancel.ThrowIfRequested("the stripe pitch");
  WorkingFeatures out;
  out.n = internal::BinningFor(result->pitch, params.tuned_pitch, params);
  result->binning = out.n;
  // The columns beside the lit pattern hold nothing to find.
  out.region =
      internal::PatternColumns(grey, out.n, params.region_rise, params.region_margin * out.n);
  result->region = out.region;
  cv::Mat working = internal::BinFrame(grey(out.region), out.n);
  if (!working.isContinuous()) working = working.clone();
  cancel.ThrowIfRequested("the pattern's columns");
  out.features = extraction::ExtractFeatures(working, params.extraction, cancel);
  result->times.extraction_ms = MsSince(t);
  return out;
}

// The interpretation of the working features, mapped to the full frame.
// Where a second core is free, the sub-pixel centres of the skeleton's
// runs are measured on it into *ahead meanwhile (centres_ahead.h); that
// stops when the interpretation ends, however that ends. Sets result's
// interpretation time and centres measured ahead.
interpretation::InterpretationResult InterpretMeasuringAhead(
    const cv::Mat& grey, pattern::Side side, const WorkingFeatures& working,
    const DecodeParams& params, const DecodeParams& subpixel, const Cancellation& cancel,
    internal::CentresAhead* ahead, DecodeResult* result) {
  std::atomic<bool> stop_ahead{false};
  std::future<void> measuring;
  struct StopAndWait {
    std::atomic<bool>& stop;
    std::future<void>& done;
    ~StopAndWait() {
      stop = true;
      if (done.valid()) done.wait();
    }
  } stop_and_wait{stop_ahead, measuring};
  if (params.measure_ahead && working.n == 1 && cv::getNumThreads() > 1)
    measuring = std::async(std::launch::async, [&] {
      *ahead = internal::CentresAhead(working.features.skeleton, working.region.tl());
      result->centres_measured_ahead = ahead->Measure(grey, subpixel.centre, stop_ahead);
    });

  const auto t = Clock::now();
  interpretation::InterpretationResult interp =
      interpretation::Interpret(working.features.skeleton, side, params.spec, params.interpretation,
                                working.features.mask, cancel);
  internal::MapToFullFrame(working.n, working.region.tl(), grey.size(), &interp);
  stop_ahead = true;
  if (measuring.valid()) measuring.get();
  result->times.interpretation_ms = MsSince(t);
  return interp;
}

// Every labelled line's sub-pixel centres, by p, with an empty entry for
// each junction's p that has no line. Lines are measured independently of
// each other: in parallel (cv::parallel_for_, OpenCV's thread pool).
std::map<int, LineCentres> MeasureLines(const cv::Mat& grey,
                                        const interpretation::InterpretationResult& interp,
                                        const internal::CentresAhead& ahead,
                                        const DecodeParams& subpixel, int n) {
  const auto& lines = interp.labelling.lines;
  std::vector<LinePixels> pixels(lines.size());
  cv::parallel_for_(cv::Range(0, static_cast<int>(lines.size())), [&](const cv::Range& r) {
    for (int i = r.start; i < r.end; ++i) pixels[i] = PrepareLine(lines[i]);
  });
  const CrowdedRows crowded = MeasureCrowdedRows(grey, lines, pixels, subpixel, n);
  std::vector<LineCentres> measured(lines.size());
  cv::parallel_for_(cv::Range(0, static_cast<int>(lines.size())), [&](const cv::Range& r) {
    for (int i = r.start; i < r.end; ++i)
      measured[i] =
          MeasureLine(grey, interp.skeleton, lines[i].p, pixels[i], crowded, ahead, subpixel, n);
  });
  std::map<int, LineCentres> centres;
  for (size_t i = 0; i < lines.size(); ++i) centres[lines[i].p] = std::move(measured[i]);
  for (const auto& j : interp.labelling.junctions) centres.try_emplace(j.p);  // read-only below
  return centres;
}

// Junctions: where the line's centre meets its segment's centre, one
// decoded junction per labelled one into result->junctions (q offset by
// q_offset). A segment is seen from both its junctions over nearly the
// same columns: the columns are gathered first and each is measured once;
// junctions are placed in parallel.
void PlaceJunctions(const cv::Mat& grey,
                    const std::vector<interpretation::LabelledJunction>& junctions,
                    const std::map<int, LineCentres>& centres, const internal::CentresAhead& ahead,
                    const DecodeParams& subpixel, int n, int q_offset, DecodeResult* result) {
  std::vector<internal::JunctionPlan> plans(junctions.size());
  cv::parallel_for_(cv::Range(0, static_cast<int>(junctions.size())), [&](const cv::Range& r) {
    for (int i = r.start; i < r.end; ++i)
      plans[i] = PlanJunction(centres.at(junctions[i].p), junctions[i], subpixel, n);
  });
  internal::ColumnCentres columns = internal::ColumnCentres::Wanted(plans);
  cv::parallel_for_(cv::Range(0, static_cast<int>(columns.keys.size())), [&](const cv::Range& r) {
    for (int i = r.start; i < r.end; ++i) {
      const auto [x, y] = columns.keys[i];
      columns.centres[i] = ahead.InColumn(grey, x, y, subpixel.centre);
    }
  });
  result->junctions.resize(junctions.size());
  cv::parallel_for_(cv::Range(0, static_cast<int>(junctions.size())), [&](const cv::Range& r) {
    for (int i = r.start; i < r.end; ++i) {
      const interpretation::LabelledJunction& j = junctions[i];
      DecodedJunction& d = result->junctions[i];
      d.p = j.p;
      d.q = j.v + q_offset;
      d.kind = j.kind;
      d.interpolated = j.interpolated;
      d.position = j.position;
      columns.Fill(&plans[i]);
      if (auto refined = internal::RefineJunction(plans[i], j.position.y, subpixel, n))
        d.position = *refined;
    }
  });
}

}  // namespace

bool TrackChainParams::IsValid(std::string* error) const {
  if (!ridge.IsValid(error) || !tracks.IsValid(error) || !labelling.IsValid(error)) return false;
  auto fail = [error](const char* why) {
    if (error) *error = why;
    return false;
  };
  if (!(smoothing_sigma > 0 && smoothing_sigma <= 10))
    return fail("track_chain.smoothing_sigma must lie in (0, 10]");
  if (!(max_centre_shift > 0)) return fail("track_chain.max_centre_shift must be positive");
  if (!(max_centre_residual > 0) || residual_rows < 2)
    return fail("track_chain.max_centre_residual must be positive and residual_rows at least 2");
  if (centre_fit_rows < 1 || centre_fit_rows > 50)
    return fail("track_chain.centre_fit_rows must lie in 1..50");
  if (segment_columns < 2) return fail("track_chain.segment_columns must be at least 2");
  if (reference_tries < 0) return fail("track_chain.reference_tries must not be negative");
  if (!(tuned_pitch > 0)) return fail("track_chain.tuned_pitch must be positive");
  if (!(native_pitch_min > 0.0 && native_pitch_min <= tuned_pitch &&
        tuned_pitch <= native_pitch_max))
    return fail("track_chain: 0 < native_pitch_min <= tuned_pitch <= native_pitch_max must hold");
  if (!(min_scale > 0.0 && min_scale <= 1.0))
    return fail("track_chain.min_scale must lie in (0, 1]");
  return true;
}

bool DecodeParams::IsValid(std::string* error) const {
  if (!spec.IsValid(error) || !extraction.IsValid(error) || !interpretation.IsValid(error) ||
      !centre.IsValid(error) || !pitch.IsValid(error) || !track_chain.IsValid(error))
    return false;
  auto fail = [error](const char* why) {
    if (error) *error = why;
    return false;
  };
  if (junction_fit_rows < 2 || junction_fit_rows > 50)
    return fail("junction_fit_rows must lie in 2..50");
  if (segment_fit_columns < 2) return fail("segment_fit_columns must be at least 2");
  if (!(max_fill_slope >= 0)) return fail("max_fill_slope must not be negative");
  if (!(steep_fill_residual >= 0 && std::isfinite(steep_fill_residual)))
    return fail("steep_fill_residual must be finite and not negative");
  if (!(fold_slope_change > 0)) return fail("fold_slope_change must be positive");
  if (!(fold_tip_spread >= 0)) return fail("fold_tip_spread must not be negative");
  if (!(crowd_distance >= 0)) return fail("crowd_distance must not be negative");
  if (junction_clearance < 0 || junction_clearance >= junction_fit_rows)
    return fail("junction_clearance must lie in 0..junction_fit_rows-1");
  if (min_dynamic_range < 0 || max_saturated_fraction <= 0 || max_saturated_fraction > 1)
    return fail("frame checks out of range");
  if (q_offset && (*q_offset % 2) != 0) return fail("q_offset must be even");
  if (!(tuned_pitch > 0)) return fail("tuned_pitch must be positive");
  if (max_binning < 1 || max_binning > 16) return fail("max_binning must lie in 1..16");
  if (!(region_rise >= 0)) return fail("region_rise must not be negative");
  if (region_margin < 0) return fail("region_margin must not be negative");
  if (binning < 0 || binning > 16) return fail("binning must lie in 0..16");
  return true;
}

DecodeParams SkeletonChainParams() {
  DecodeParams params;
  params.chain = DecodeChain::kSkeleton;
  return params;
}

std::optional<DecodeChain> ChainFor(std::optional<DecodeChain> named, const DecodeParams& params,
                                    std::string* why) {
  const bool thesis_extraction = params.extraction.method != extraction::ExtractionMethod::kModern;
  const bool no_repair = !params.interpretation.enable_repair;
  if (!named) {
    if (thesis_extraction || no_repair) return DecodeChain::kSkeleton;
    return params.chain;
  }
  if (*named == DecodeChain::kTracks && (thesis_extraction || no_repair)) {
    if (why)
      *why = std::string(thesis_extraction ? "the thesis's feature extraction" : "no repair") +
             " is an option of the skeleton chain, not of the track chain";
    return std::nullopt;
  }
  return named;
}

DecodeResult Decode(const cv::Mat& grey, pattern::Side side, const DecodeParams& params,
                    const Cancellation& cancel) {
  if (grey.empty() || grey.type() != CV_8UC1)
    throw std::invalid_argument("Decode: frame must be a non-empty CV_8UC1 image");
  std::string why;
  if (!params.IsValid(&why)) throw std::invalid_argument("Decode: " + why);

  const auto start = Clock::now();
  DecodeResult result;
  result.side = side;
  result.width = grey.cols;
  result.height = grey.rows;
  result.q_absolute = params.q_offset.has_value();
  if (std::string bad = CheckFrame(grey, params); !bad.empty()) {
    result.error = bad;
    result.times.total_ms = MsSince(start);
    return result;
  }
  if (params.chain == DecodeChain::kTracks) {
    internal::DecodeByTracks(grey, side, params, cancel, &result);
    result.times.total_ms = MsSince(start);
    return result;
  }

  const WorkingFeatures working = ExtractWorkingFeatures(grey, params, cancel, &result);
  cancel.ThrowIfRequested("the feature extraction");

  const DecodeParams subpixel = ScaledForBinning(params, working.n);
  internal::CentresAhead ahead;
  const interpretation::InterpretationResult interp =
      InterpretMeasuringAhead(grey, side, working, params, subpixel, cancel, &ahead, &result);
  result.skeleton = interp.skeleton;
  result.repairs = static_cast<int>(interp.repairs.size());
  result.loop_classes = interp.loop_classes;
  result.label_conflicts = interp.labelling.conflicts;
  if (!interp.ok) {
    result.error = interp.error;
    result.times.total_ms = MsSince(start);
    return result;
  }
  cancel.ThrowIfRequested("the interpretation");

  const auto t = Clock::now();
  std::map<int, LineCentres> centres = MeasureLines(grey, interp, ahead, subpixel, working.n);
  PlaceJunctions(grey, interp.labelling.junctions, centres, ahead, subpixel, working.n,
                 params.q_offset.value_or(0), &result);
  // Lines: their decoded points (MeasureLine).
  for (const interpretation::LabelledLine& line : interp.labelling.lines) {
    DecodedLine out;
    out.p = line.p;
    out.points = centres[line.p].points;
    if (!out.points.empty()) result.lines.push_back(std::move(out));
  }
  result.times.subpixel_ms = MsSince(t);
  result.ok = true;
  result.times.total_ms = MsSince(start);
  return result;
}

}  // namespace bsls::decoder
