#include "bsls/decoder/decoder.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <map>
#include <opencv2/imgproc.hpp>
#include <optional>
#include <set>
#include <stdexcept>

namespace bsls::decoder {
namespace {

using Clock = std::chrono::steady_clock;

double MsSince(Clock::time_point t) {
  return std::chrono::duration<double, std::milli>(Clock::now() - t).count();
}

// Says why a frame cannot carry the pattern, or returns an empty string.
std::string CheckFrame(const cv::Mat& grey, const DecodeParams& params) {
  int histogram[256] = {0};
  for (int y = 0; y < grey.rows; ++y) {
    const uchar* row = grey.ptr<uchar>(y);
    for (int x = 0; x < grey.cols; ++x) ++histogram[row[x]];
  }
  const double total = static_cast<double>(grey.total());
  auto percentile = [&](double f) {
    double acc = 0;
    for (int i = 0; i < 256; ++i) {
      acc += histogram[i];
      if (acc >= f * total) return i;
    }
    return 255;
  };
  const int lo = percentile(0.01), hi = percentile(0.99);
  const double saturated = (histogram[254] + histogram[255]) / total;
  if (saturated > params.max_saturated_fraction)
    return "frame is saturated (" + std::to_string(static_cast<int>(saturated * 100)) +
           "% of pixels at full scale)";
  if (hi - lo < params.min_dynamic_range && percentile(0.999) - lo < params.min_dynamic_range)
    return "frame is blank (grey levels " + std::to_string(lo) + ".." + std::to_string(hi) +
           " hold 98% of pixels)";
  return {};
}

// Least-squares line x = a + b t through (t, x) samples; false with < 2 samples.
bool FitLine(const std::vector<std::pair<double, double>>& s, double* a, double* b) {
  if (s.size() < 2) return false;
  double st = 0, sx = 0, stt = 0, stx = 0;
  for (const auto& [t, x] : s) {
    st += t;
    sx += x;
    stt += t * t;
    stx += t * x;
  }
  const double n = static_cast<double>(s.size());
  const double den = n * stt - st * st;
  if (std::abs(den) < 1e-9) return false;
  *b = (n * stx - st * sx) / den;
  *a = (sx - *b * st) / n;
  return true;
}

// Least-squares x = c0 + c1 t + c2 t^2 through (t, x) samples; false when
// there are fewer than five or they do not fix a parabola.
bool FitParabola(const std::vector<std::pair<double, double>>& s, cv::Vec3d* c) {
  if (s.size() < 5) return false;
  cv::Matx33d ata = cv::Matx33d::zeros();
  cv::Vec3d atb(0, 0, 0);
  for (const auto& [t, x] : s) {
    const cv::Vec3d row(1.0, t, t * t);
    for (int i = 0; i < 3; ++i) {
      atb[i] += row[i] * x;
      for (int k = 0; k < 3; ++k) ata(i, k) += row[i] * row[k];
    }
  }
  return cv::solve(ata, atb, *c, cv::DECOMP_CHOLESKY);
}

// The value at t = 0 of a parabola through (t, x) samples (a line when there
// are fewer than five), or nullopt.
std::optional<double> FitAtZero(const std::vector<std::pair<double, double>>& s) {
  cv::Vec3d c;
  if (FitParabola(s, &c)) return c[0];
  double a, b;
  if (!FitLine(s, &a, &b)) return std::nullopt;
  return a;
}

// The rows of `rows` within `radius` of `centre` and farther than `exclude`
// from it, as (row - centre, x) pairs for the fits above.
std::vector<std::pair<double, double>> RowsNear(const std::map<int, double>& rows, double centre,
                                                int radius, double exclude) {
  std::vector<std::pair<double, double>> out;
  for (auto it = rows.lower_bound(cvFloor(centre) - radius);
       it != rows.end() && it->first <= centre + radius; ++it)
    if (std::abs(it->first - centre) > exclude) out.push_back({it->first - centre, it->second});
  return out;
}

struct LineCentres {
  std::map<int, double> measured;  // row -> sub-pixel x, outliers removed
  std::map<int, double> skeleton;  // row -> mean x of the line's skeleton pixels
  std::map<int, double> slope;     // row -> |dx/dy| of the skeleton there
  std::set<int> skipped;           // rows crossed but not measured (beside a segment)
};

// True when the skeleton has a segment leaving the line near (x, y): a set
// pixel 2-4 columns to either side within `clearance` rows that is not part of
// the line itself.
bool SegmentNearby(const cv::Mat& skeleton, const std::set<std::pair<int, int>>& own, int x, int y,
                   int clearance) {
  for (int dy = -clearance; dy <= clearance; ++dy) {
    const int yy = y + dy;
    if (yy < 0 || yy >= skeleton.rows) continue;
    const uchar* row = skeleton.ptr<uchar>(yy);
    for (int k = 2; k <= 4; ++k)
      for (int xx : {x - k, x + k})
        if (xx >= 0 && xx < skeleton.cols && row[xx] && !own.count({xx, yy})) return true;
  }
  return false;
}

// |dx/dy| of a line's skeleton over three rows each side of row y (0 when unknown).
double LocalSlope(const std::map<int, double>& skeleton, int y) {
  const auto a = skeleton.lower_bound(y - 3);
  const auto b = skeleton.upper_bound(y + 3);
  if (a == skeleton.end() || b == skeleton.begin()) return 0.0;
  const auto last = std::prev(b);
  if (last->first <= a->first) return 0.0;
  return std::abs((last->second - a->second) / (last->first - a->first));
}

// Sub-pixel centres of one labelled line, one per row its skeleton crosses.
// Rows beside a segment are skipped (the segment's light biases them), and a
// centre far from the fit of its neighbours is dropped as an outlier.
LineCentres MeasureLine(const cv::Mat& grey, const cv::Mat& skeleton,
                        const interpretation::LabelledLine& line, const DecodeParams& params) {
  std::map<int, std::pair<int, int>> span;  // row -> (min x, max x)
  std::set<std::pair<int, int>> own;
  for (const cv::Point& p : line.pixels) {
    own.insert({p.x, p.y});
    auto [it, fresh] = span.try_emplace(p.y, p.x, p.x);
    if (!fresh) {
      it->second.first = std::min(it->second.first, p.x);
      it->second.second = std::max(it->second.second, p.x);
    }
  }
  LineCentres out;
  for (const auto& [y, range] : span)
    if (range.second - range.first <= 2) out.skeleton[y] = 0.5 * (range.first + range.second);
  for (const auto& [y, range] : span) {
    const auto [lo, hi] = range;
    // A steep line's row profile is wide, so a segment biases more rows of it.
    const double slope = LocalSlope(out.skeleton, y);
    out.slope[y] = slope;
    const int clearance =
        params.junction_clearance +
        static_cast<int>(std::lround(2.0 * params.junction_clearance *
                                     std::max(0.0, slope - params.max_fill_slope)));
    const int x = (lo + hi) / 2;
    // A row where the skeleton runs sideways is a segment, not the line.
    if (hi - lo > 2 || SegmentNearby(skeleton, own, x, y, clearance)) {
      out.skipped.insert(y);
      continue;
    }
    if (auto cx = extraction::StripeCentreInRow(grey, y, 0.5 * (lo + hi), params.centre))
      out.measured[y] = *cx;
    else
      out.skipped.insert(y);
  }
  // Outliers: more than max_centre_residual from the line through the
  // neighbours within junction_fit_rows.
  std::vector<int> outliers;
  for (const auto& [y, x] : out.measured) {
    const auto s = RowsNear(out.measured, y, params.junction_fit_rows, 0.0);
    if (s.size() < 4) continue;
    const auto fit = FitAtZero(s);
    if (fit && std::abs(x - *fit) > params.max_centre_residual) outliers.push_back(y);
  }
  for (int y : outliers) {
    out.measured.erase(y);
    out.skipped.insert(y);
  }
  return out;
}

// The junction where the line's centre curve meets the segment's: the line's
// measured centres near the junction fitted as x(y), the segment's centres
// measured column by column along its skeleton and fitted as y(x). An
// interpolated junction, or one whose segment cannot be measured, is placed on
// the line's fit at its row. nullopt when the line has too few centres near it.
std::optional<cv::Point2d> RefineJunction(const cv::Mat& grey, const LineCentres& line,
                                          const interpretation::LabelledJunction& j,
                                          const DecodeParams& params) {
  const double y0 = j.position.y;
  // The line as x(y): sub-pixel centres, or where a steep or crowded line has
  // too few of them, its skeleton (within a pixel of the centre).
  double a, b;
  std::vector<std::pair<double, double>> vertical =
      RowsNear(line.measured, y0, params.junction_fit_rows, 0.0);
  if (vertical.size() < 3 || !FitLine(vertical, &a, &b)) {
    vertical = RowsNear(line.skeleton, y0, params.junction_fit_rows, 1.0);
    if (vertical.size() < 3 || !FitLine(vertical, &a, &b)) return std::nullopt;
  }
  double y = y0;
  if (!j.interpolated && !j.segment.empty()) {
    // The segment as y(x): centres column by column along its skeleton, or the
    // skeleton itself; its ends are skipped, where the lines' light biases it.
    std::vector<std::pair<double, double>> measured, skeleton;  // (x - a, y)
    const int n = static_cast<int>(j.segment.size());
    for (int i = 0; i < n - 2 && static_cast<int>(skeleton.size()) < params.segment_fit_columns;
         ++i) {
      const cv::Point& s = j.segment[i];
      if (std::abs(s.x - a) <= params.junction_clearance) continue;
      skeleton.push_back({s.x - a, static_cast<double>(s.y)});
      if (auto cy = extraction::StripeCentreInColumn(grey, s.x, s.y, params.centre))
        measured.push_back({s.x - a, *cy});
    }
    double c, e;
    const bool fitted = (measured.size() >= 2 && FitLine(measured, &c, &e)) ||
                        (skeleton.size() >= 2 && FitLine(skeleton, &c, &e));
    if (fitted) {
      // Where x = a' + b' (y - y0) meets y = c + e (x - a):
      //   y = (c + e (a' - a) - e b' y0) / (1 - e b').
      auto meet = [&](double a2, double b2, double* out) {
        const double den = 1.0 - e * b2;
        if (std::abs(den) < 1e-6) return false;
        *out = (c + e * (a2 - a) - e * b2 * y0) / den;
        return std::abs(*out - y0) <= params.junction_clearance + 1.0;
      };
      std::vector<std::pair<double, double>> upper, lower;
      for (const auto& v : vertical) (v.first < 0 ? upper : lower).push_back(v);
      double au, bu, al, bl, yu, yl, ya;
      const bool branches = upper.size() >= 2 && lower.size() >= 2 && FitLine(upper, &au, &bu) &&
                            FitLine(lower, &al, &bl);
      // A line folding at its junction (nose, lips): the branches above and
      // below meet the segment each on its own, and the junction lies between
      // the two meeting points.
      if (branches && std::abs(bu - bl) > params.fold_slope_change) {
        if (meet(au, bu, &yu) && meet(al, bl, &yl)) {
          const double xu = au + bu * (yu - y0), xl = al + bl * (yl - y0);
          return cv::Point2d(0.5 * (xu + xl), 0.5 * (yu + yl));
        }
      } else if (cv::Vec3d k; branches && FitParabola(vertical, &k)) {
        // A line curving smoothly through it: its centres on both sides as a
        // parabola x = k0 + k1 t + k2 t^2 (t = y - y0), which meets the segment
        // where e k2 t^2 + (e k1 - 1) t + c + e (k0 - a) - y0 = 0; the root
        // nearer t = 0, in the form that stays exact as e k2 -> 0.
        const double qa = e * k[2], qb = e * k[1] - 1.0, qc = c + e * (k[0] - a) - y0;
        const double disc = qb * qb - 4 * qa * qc;
        if (disc >= 0) {
          const double t = 2 * qc / (-qb + std::copysign(std::sqrt(disc), -qb));
          if (std::abs(t) <= params.junction_clearance + 1.0)
            return cv::Point2d(k[0] + k[1] * t + k[2] * t * t, y0 + t);
        }
      }
      if (meet(a, b, &ya)) y = ya;
    }
  }
  return cv::Point2d(a + b * (y - y0), y);
}

}  // namespace

bool DecodeParams::IsValid(std::string* error) const {
  if (!spec.IsValid(error) || !extraction.IsValid(error) || !interpretation.IsValid(error) ||
      !centre.IsValid(error))
    return false;
  auto fail = [error](const char* why) {
    if (error) *error = why;
    return false;
  };
  if (junction_fit_rows < 2 || junction_fit_rows > 50)
    return fail("junction_fit_rows must lie in 2..50");
  if (segment_fit_columns < 2) return fail("segment_fit_columns must be at least 2");
  if (!(max_fill_slope >= 0)) return fail("max_fill_slope must not be negative");
  if (!(fold_slope_change > 0)) return fail("fold_slope_change must be positive");
  if (junction_clearance < 0 || junction_clearance >= junction_fit_rows)
    return fail("junction_clearance must lie in 0..junction_fit_rows-1");
  if (min_dynamic_range < 0 || max_saturated_fraction <= 0 || max_saturated_fraction > 1)
    return fail("frame checks out of range");
  if (q_offset && (*q_offset % 2) != 0) return fail("q_offset must be even");
  return true;
}

DecodeResult Decode(const cv::Mat& grey, pattern::Side side, const DecodeParams& params) {
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

  auto t = Clock::now();
  const extraction::ExtractionResult features =
      extraction::ExtractFeatures(grey, params.extraction);
  result.times.extraction_ms = MsSince(t);

  t = Clock::now();
  const interpretation::InterpretationResult interp = interpretation::Interpret(
      features.skeleton, side, params.spec, params.interpretation, features.mask);
  result.times.interpretation_ms = MsSince(t);
  result.skeleton = interp.skeleton;
  result.repairs = static_cast<int>(interp.repairs.size());
  result.loop_classes = interp.loop_classes;
  result.label_conflicts = interp.labelling.conflicts;
  if (!interp.ok) {
    result.error = interp.error;
    result.times.total_ms = MsSince(start);
    return result;
  }

  t = Clock::now();
  const int q_offset = params.q_offset.value_or(0);
  std::map<int, std::vector<const interpretation::LabelledJunction*>> junctions_of_line;
  for (const auto& j : interp.labelling.junctions) junctions_of_line[j.p].push_back(&j);
  // Lines, then junctions, are measured independently of each other: in
  // parallel (cv::parallel_for_, OpenCV's thread pool).
  const auto& lines = interp.labelling.lines;
  std::vector<LineCentres> measured(lines.size());
  cv::parallel_for_(cv::Range(0, static_cast<int>(lines.size())), [&](const cv::Range& r) {
    for (int i = r.start; i < r.end; ++i)
      measured[i] = MeasureLine(grey, interp.skeleton, lines[i], params);
  });
  std::map<int, LineCentres> centres;
  for (size_t i = 0; i < lines.size(); ++i) centres[lines[i].p] = std::move(measured[i]);
  for (const auto& j : interp.labelling.junctions) centres.try_emplace(j.p);  // read-only below

  // Junctions: where the line's centre meets its segment's centre.
  const auto& junctions = interp.labelling.junctions;
  result.junctions.resize(junctions.size());
  cv::parallel_for_(cv::Range(0, static_cast<int>(junctions.size())), [&](const cv::Range& r) {
    for (int i = r.start; i < r.end; ++i) {
      const interpretation::LabelledJunction& j = junctions[i];
      DecodedJunction& d = result.junctions[i];
      d.p = j.p;
      d.q = j.v + q_offset;
      d.kind = j.kind;
      d.interpolated = j.interpolated;
      d.position = j.position;
      if (auto refined = RefineJunction(grey, centres.at(j.p), j, params)) d.position = *refined;
    }
  });

  // Lines: measured centres, and the skipped rows filled from the line's own
  // fit where measured rows lie on both sides.
  for (const interpretation::LabelledLine& line : interp.labelling.lines) {
    DecodedLine out;
    out.p = line.p;
    const LineCentres& lc = centres[line.p];
    std::map<int, double> points = lc.measured;
    for (int y : lc.skipped) {
      // Rows of a steep stretch are not invented: its fit is not good enough.
      const auto slope = lc.slope.find(y);
      if (slope != lc.slope.end() && slope->second > params.max_fill_slope) continue;
      const auto s = RowsNear(lc.measured, y, params.junction_fit_rows, 0.0);
      const bool above = std::any_of(s.begin(), s.end(), [](const auto& r) { return r.first < 0; });
      const bool below = std::any_of(s.begin(), s.end(), [](const auto& r) { return r.first > 0; });
      if (!above || !below || s.size() < 4) continue;
      if (const auto fit = FitAtZero(s)) points[y] = *fit;
    }
    for (const auto& [y, x] : points) out.points.emplace_back(x, y);
    if (!out.points.empty()) result.lines.push_back(std::move(out));
  }
  result.times.subpixel_ms = MsSince(t);
  result.ok = true;
  result.times.total_ms = MsSince(start);
  return result;
}

}  // namespace bsls::decoder
