#include "bsls/extraction/thinning.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdlib>
#include <iterator>
#include <limits>
#include <opencv2/imgproc.hpp>
#include <optional>
#include <vector>

#include "bands.h"
#include "input_checks.h"
#include "neighbourhood.h"
#include "skeleton_in_place.h"

namespace bsls::extraction {
namespace {

using internal::CodeTable;
using internal::GaussianBandsInto;
using internal::GaussianInto;
using internal::MakeCodeTable;
using internal::Neighbours;
using internal::PaddedBinary;
using internal::RequireGrey8;
using internal::RequireValid;

// ---------------------------------------------------------------------------
// Thesis 4.3.1: line-following thinning.

struct Run {
  int lo = 0;  // first set pixel along the scan axis
  int hi = 0;  // last set pixel, inclusive
  int Mid() const { return (lo + hi) / 2; }
};

// A deferred join: from a trace end, the nearest skeleton pixel inside the
// box reaching `reach` pixels along (dx, dy) and `band` pixels across it.
struct Link {
  cv::Point from;
  int dx = 0;
  int dy = 0;
  int reach = 0;
  int band = 0;
};

struct VerticalTask {
  int y = 0;
  Run run;
  std::optional<cv::Point> join_from;  // skeleton pixel this branch leaves
};

class LineFollower {
 public:
  LineFollower(const cv::Mat& binary, const LineFollowingParams& params)
      : img_(binary != 0), skel_(cv::Mat::zeros(binary.size(), CV_8UC1)), p_(params) {}

  cv::Mat Thin() {
    // Raster scan, rows top to bottom, each row right to left (thesis 4.3.1).
    for (int y = 0; y < img_.rows; ++y) {
      const unsigned char* row = img_.ptr<unsigned char>(y);
      for (int x = img_.cols - 1; x >= 0; --x) {
        if (!row[x]) continue;
        StartAt(x, y);
        Erase(x, y);  // progress even when the start pixel was left to a junction
      }
    }
    for (const Link& link : links_) Resolve(link);
    return skel_;
  }

 private:
  bool At(int x, int y) const {
    return x >= 0 && y >= 0 && x < img_.cols && y < img_.rows && img_.at<unsigned char>(y, x);
  }
  void Erase(int x, int y) {
    if (x >= 0 && y >= 0 && x < img_.cols && y < img_.rows) img_.at<unsigned char>(y, x) = 0;
  }
  // Writes a skeleton pixel and joins it to the previous one of its trace.
  void Mark(cv::Point p, std::optional<cv::Point>* prev) {
    if (*prev && (std::abs(p.x - (*prev)->x) > 1 || std::abs(p.y - (*prev)->y) > 1))
      cv::line(skel_, **prev, p, 255, 1, cv::LINE_8);
    skel_.at<unsigned char>(p) = 255;
    *prev = p;
  }

  // Maximal runs of set pixels of row y (column x) inside [a, b], clamped.
  std::vector<Run> RowRuns(int y, int a, int b) const {
    return Runs(a, b, img_.cols, [&](int i) { return At(i, y); });
  }
  std::vector<Run> ColRuns(int x, int a, int b) const {
    return Runs(a, b, img_.rows, [&](int i) { return At(x, i); });
  }
  template <typename IsSet>
  static std::vector<Run> Runs(int a, int b, int length, IsSet is_set) {
    std::vector<Run> runs;
    a = std::max(a, 0);
    b = std::min(b, length - 1);
    for (int i = a; i <= b; ++i) {
      if (!is_set(i)) continue;
      int j = i;
      while (j + 1 <= b && is_set(j + 1)) ++j;
      runs.push_back({i, j});
      i = j;
    }
    return runs;
  }
  // Runs separated by at most bridge_gap black pixels are one run.
  std::vector<Run> Bridged(const std::vector<Run>& runs) const {
    std::vector<Run> out;
    for (const Run& r : runs) {
      if (!out.empty() && r.lo - out.back().hi - 1 <= p_.bridge_gap)
        out.back().hi = r.hi;
      else
        out.push_back(r);
    }
    return out;
  }
  // The run through a set pixel at `i`, grown both ways across gaps of up to
  // bridge_gap black pixels.
  template <typename IsSet>
  Run Grow(int i, IsSet is_set) const {
    Run r{i, i};
    for (bool grown = true; grown;) {
      grown = false;
      for (int k = 1; k <= p_.bridge_gap + 1; ++k)
        if (is_set(r.lo - k)) {
          r.lo -= k;
          grown = true;
          break;
        }
      for (int k = 1; k <= p_.bridge_gap + 1; ++k)
        if (is_set(r.hi + k)) {
          r.hi += k;
          grown = true;
          break;
        }
    }
    return r;
  }
  Run GrowRow(int x, int y) const {
    return Grow(x, [&](int i) { return At(i, y); });
  }
  Run GrowCol(int x, int y) const {
    return Grow(y, [&](int i) { return At(x, i); });
  }
  // Number of consecutive set pixels from (x, y) stepping by (dx, dy).
  int Extent(int x, int y, int dx, int dy, int limit) const {
    int n = 0;
    while (n < limit && At(x + n * dx, y + n * dy)) ++n;
    return n;
  }

  void StartAt(int x, int y) {
    const Run row_run = GrowRow(x, y);
    const int m = row_run.Mid();
    const int width = row_run.hi - row_run.lo + 1;
    // Height: rows from y down whose window [lo - l, hi + l] holds set pixels.
    const int cap = 2 * width + p_.margin + 1;
    int height = 0;
    while (height < cap &&
           !RowRuns(y + height, row_run.lo - p_.margin, row_run.hi + p_.margin).empty())
      ++height;
    if (width > 2 * height + p_.margin) {
      // Wider than tall: a horizontal structure, followed both ways from its middle.
      const Run left_run = GrowCol(m, y);
      std::optional<Run> right_run;
      const auto right = ColRuns(m + 1, left_run.lo - p_.margin, left_run.hi + p_.margin);
      if (!right.empty()) right_run = Run{right.front().lo, right.back().hi};
      const cv::Point first = FollowHorizontal(m, left_run, -1);
      if (right_run) {
        const cv::Point second = FollowHorizontal(m + 1, *right_run, +1);
        cv::line(skel_, first, second, 255, 1, cv::LINE_8);
      }
      return;
    }
    FollowVertical({y, row_run, std::nullopt});
  }

  // Thesis 4.3.1, vertical (main) following with the adaptive window.
  void FollowVertical(const VerticalTask& start) {
    std::vector<VerticalTask> pending{start};
    while (!pending.empty()) {
      const VerticalTask task = pending.back();
      pending.pop_back();
      const auto live = RowRuns(task.y, task.run.lo, task.run.hi);
      if (live.empty()) continue;  // taken by another trace meanwhile
      Run run{live.front().lo, live.back().hi};
      int y = task.y;
      int split_rows = 0;
      int held_rows = 0;
      std::optional<cv::Point> prev;
      bool first = true;
      for (;;) {
        for (int x = run.lo; x <= run.hi; ++x) Erase(x, y);
        const cv::Point median(run.Mid(), y);
        if (first && task.join_from) cv::line(skel_, *task.join_from, median, 255, 1, cv::LINE_8);
        first = false;
        Mark(median, &prev);
        const int ny = y + 1;
        if (ny >= img_.rows) break;
        const int wl = std::max(0, run.lo - p_.margin);
        const int wr = std::min(img_.cols - 1, run.hi + p_.margin);
        const std::vector<Run> subs = Bridged(RowRuns(ny, wl, wr));
        if (subs.empty()) {  // End_of_line
          links_.push_back({median, 0, 1, p_.margin + 1, (run.hi - run.lo) / 2 + p_.margin});
          break;
        }
        // Junction: the set pixels leave the window sideways.
        const bool right = At(wr, ny) && SideBranch(wr + 1, ny, +1);
        const bool left = At(wl, ny) && SideBranch(wl - 1, ny, -1);
        Run next;
        if (subs.size() > 1 && ++split_rows > p_.max_split_rows) {
          // A split lasting too long: a fork. Follow the branch nearest the
          // median, the others later, each joined to this median.
          size_t nearest = 0;
          int best = img_.cols;
          for (size_t i = 0; i < subs.size(); ++i) {
            const int d = std::max({0, subs[i].lo - median.x, median.x - subs[i].hi});
            if (d < best) {
              best = d;
              nearest = i;
            }
          }
          for (size_t i = 0; i < subs.size(); ++i)
            if (i != nearest) pending.push_back({ny, subs[i], median});
          next = subs[nearest];
          split_rows = 0;
          held_rows = p_.max_split_rows;  // the branch is narrower by nature
        } else if (subs.size() > 1) {
          next = {subs.front().lo, subs.back().hi};  // black pixels inside: assume white
        } else {
          split_rows = 0;
          next = subs.front();
          // A run that suddenly loses one side (a flank edge opening where a
          // branch leaves, or a hole at the side) keeps its extent for up to
          // max_split_rows rows: "assume all the pixels are white".
          const bool shrunk = next.hi - next.lo < run.hi - run.lo - p_.bridge_gap;
          if (shrunk && held_rows < p_.max_split_rows) {
            next = {std::min(next.lo, run.lo), std::max(next.hi, run.hi)};
            ++held_rows;
          } else if (!shrunk) {
            held_rows = 0;
          }
        }
        // On a junction row keep the run on the line, not on the branch.
        if (right) next.hi = std::max(next.lo, std::min(next.hi, run.hi + 1));
        if (left) next.lo = std::min(next.hi, std::max(next.lo, run.lo - 1));
        if (right) FollowBranch(ny, next, wr + 1, +1);
        if (left) FollowBranch(ny, next, wl - 1, -1);
        run = next;
        y = ny;
      }
    }
  }

  // True when at least min_branch_length set pixels continue from (x, y)
  // along dx; shorter bumps are erased as noise.
  bool SideBranch(int x, int y, int dx) {
    const int n = Extent(x, y, dx, 0, p_.min_branch_length);
    if (n >= p_.min_branch_length) return true;
    for (int i = 0; i < n; ++i) Erase(x + i * dx, y);
    return false;
  }

  // Thesis 4.3.1, junction: follow the horizontal branch leaving the
  // vertical line (run `line_run` of row y) at column `start` along dx.
  void FollowBranch(int y, const Run& line_run, int start, int dx) {
    const Run branch = GrowCol(start, y);
    const cv::Point first = FollowHorizontal(start, branch, dx);
    // Erase the corner between the line's run and the branch start.
    const int a = dx > 0 ? line_run.hi + 1 : start + 1;
    const int b = dx > 0 ? start - 1 : line_run.lo - 1;
    for (int r = branch.lo; r <= branch.hi; ++r)
      for (int c = a; c <= b; ++c) Erase(c, r);
    // Join the branch to the line's skeleton once that exists (deferred).
    links_.push_back({first, -dx, 0, std::abs(start - line_run.Mid()) + 2, 1});
  }

  // Thesis 4.3.1, horizontal following from column x (run along the column)
  // in direction dx until a junction or the end of the line. Returns the
  // first skeleton pixel.
  cv::Point FollowHorizontal(int x, Run run, int dx) {
    std::optional<cv::Point> prev;
    cv::Point first;
    bool is_first = true;
    for (;;) {
      for (int r = run.lo; r <= run.hi; ++r) Erase(x, r);
      const cv::Point median(x, run.Mid());
      Mark(median, &prev);
      if (is_first) first = median;
      is_first = false;
      const int nx = x + dx;
      if (nx < 0 || nx >= img_.cols) break;
      const int wt = std::max(0, run.lo - p_.margin);
      const int wb = std::min(img_.rows - 1, run.hi + p_.margin);
      const std::vector<Run> subs = Bridged(ColRuns(nx, wt, wb));
      if (subs.empty()) {  // End_of_line
        links_.push_back({median, dx, 0, p_.margin + 2, p_.margin});
        break;
      }
      const bool up =
          At(nx, wt) && Extent(nx, wt - 1, 0, -1, p_.min_branch_length) >= p_.min_branch_length;
      const bool down =
          At(nx, wb) && Extent(nx, wb + 1, 0, 1, p_.min_branch_length) >= p_.min_branch_length;
      if (up || down) {
        // The next junction: a vertical line. Stop; it is followed on its own
        // and this branch is joined to its skeleton.
        const int line_width = Extent(nx, median.y, dx, 0, 4 * img_.cols);
        links_.push_back({median, dx, 0, line_width + p_.margin + 2, 2});
        break;
      }
      for (int k = 1; At(nx, wt - k); ++k) Erase(nx, wt - k);  // short bumps
      for (int k = 1; At(nx, wb + k); ++k) Erase(nx, wb + k);
      run = {subs.front().lo, subs.back().hi};
      x = nx;
    }
    return first;
  }

  void Resolve(const Link& link) {
    // Box ahead of the trace end: along (dx, dy) from 1 to reach, +-band across.
    std::optional<cv::Point> best;
    int best_d2 = 0;
    for (int along = 1; along <= link.reach; ++along)
      for (int across = -link.band; across <= link.band; ++across) {
        const cv::Point q = link.dx != 0
                                ? cv::Point(link.from.x + along * link.dx, link.from.y + across)
                                : cv::Point(link.from.x + across, link.from.y + along * link.dy);
        if (q.x < 0 || q.y < 0 || q.x >= skel_.cols || q.y >= skel_.rows) continue;
        if (!skel_.at<unsigned char>(q)) continue;
        const int d2 =
            (q.x - link.from.x) * (q.x - link.from.x) + (q.y - link.from.y) * (q.y - link.from.y);
        if (!best || d2 < best_d2) {
          best = q;
          best_d2 = d2;
        }
      }
    if (best) cv::line(skel_, link.from, *best, 255, 1, cv::LINE_8);
  }

  cv::Mat img_;   // working copy, erased as the lines are followed (0/255)
  cv::Mat skel_;  // the skeleton being written (0/255)
  LineFollowingParams p_;
  std::vector<Link> links_;
};

// ---------------------------------------------------------------------------
// Thesis 4.3.2: Zhang-Suen.

// Conditions of eq. 4.18 (step 0) or eq. 4.20 (step 1) on a neighbourhood.
bool ZhangSuenDeletable(const Neighbours& n, int step) {
  const int count = n.Count();
  if (count < 2 || count > 6) return false;                                  // (a)
  if (n.Transitions() != 1) return false;                                    // (b)
  if (step == 0) return !(n.p2 && n.p4 && n.p6) && !(n.p4 && n.p6 && n.p8);  // (c), (d)
  return !(n.p2 && n.p4 && n.p8) && !(n.p2 && n.p6 && n.p8);                 // (c'), (d')
}

// ZhangSuenDeletable for every neighbourhood code, per step.
const CodeTable& ZhangSuenTable(int step) {
  static const CodeTable tables[2] = {
      MakeCodeTable([](const Neighbours& n) { return ZhangSuenDeletable(n, 0); }),
      MakeCodeTable([](const Neighbours& n) { return ZhangSuenDeletable(n, 1); })};
  return tables[step];
}

// Deleting the pixel changes no topology and shortens no line: at least two
// set neighbours and 8-simple.
bool Simple(const Neighbours& n) { return n.Count() >= 2 && n.ConnectivityNumber8() == 1; }

// Simple for every neighbourhood code.
const CodeTable& SimpleTable() {
  static const CodeTable table = MakeCodeTable(Simple);
  return table;
}

// What MakeOnePixelWide deletes: simple pixels, except T-centres (three or
// four set 4-neighbours) when they are kept.
const CodeTable& ThinnableTable(TJunctionShape t_junctions) {
  static const CodeTable keep_centres =
      MakeCodeTable([](const Neighbours& n) { return Simple(n) && n.p2 + n.p4 + n.p6 + n.p8 < 3; });
  static const CodeTable notched = MakeCodeTable(Simple);
  return t_junctions == TJunctionShape::kCentreKept ? keep_centres : notched;
}

}  // namespace

bool LineFollowingParams::IsValid(std::string* error) const {
  auto fail = [error](const char* why) {
    if (error) *error = why;
    return false;
  };
  if (margin < 1 || margin > 16) return fail("line-following margin must lie in 1..16 px");
  if (max_split_rows < 0 || max_split_rows > 100) return fail("max_split_rows must lie in 0..100");
  if (bridge_gap < 0 || bridge_gap > 32) return fail("bridge_gap must lie in 0..32 px");
  if (min_branch_length < 1 || min_branch_length > 100)
    return fail("min_branch_length must lie in 1..100 px");
  return true;
}

bool ZhangSuenParams::IsValid(std::string* error) const {
  if (max_iterations < 1) {
    if (error) *error = "Zhang-Suen max_iterations must be >= 1";
    return false;
  }
  return true;
}

cv::Mat LineFollowingThin(const cv::Mat& binary, const LineFollowingParams& params) {
  RequireGrey8(binary, "LineFollowingThin", "binary image");
  RequireValid(params, "LineFollowingThin");
  return LineFollower(binary, params).Thin();
}

cv::Mat ZhangSuenThin(const cv::Mat& binary, const ZhangSuenParams& params) {
  RequireGrey8(binary, "ZhangSuenThin", "binary image");
  RequireValid(params, "ZhangSuenThin");
  PaddedBinary img(binary);
  internal::ZhangSuenThinInPlace(&img, params);
  return img.ToMat();
}

cv::Mat MakeOnePixelWide(const cv::Mat& skeleton, TJunctionShape t_junctions) {
  RequireGrey8(skeleton, "MakeOnePixelWide", "skeleton");
  PaddedBinary img(skeleton);
  internal::MakeOnePixelWideInPlace(&img, t_junctions);
  return img.ToMat();
}

bool RecentreParams::IsValid(std::string* error) const {
  auto fail = [error](const char* why) {
    if (error) *error = why;
    return false;
  };
  if (!(sigma > 0.0 && sigma <= 20.0)) return fail("recentre sigma must lie in (0, 20] px");
  if (!(min_gain >= 0.0)) return fail("recentre min_gain must be >= 0");
  if (passes < 1 || passes > 20) return fail("recentre passes must lie in 1..20");
  if (junction_clearance < 0 || junction_clearance > 50)
    return fail("recentre junction_clearance must lie in 0..50 px");
  return true;
}

cv::Mat RecentreOnRidge(const cv::Mat& skeleton, const cv::Mat& grey,
                        const RecentreParams& params) {
  RequireGrey8(skeleton, "RecentreOnRidge", "skeleton");
  RequireGrey8(grey, "RecentreOnRidge", "grey image");
  RequireValid(params, "RecentreOnRidge");
  if (grey.size() != skeleton.size())
    throw std::invalid_argument("RecentreOnRidge: skeleton and grey image differ in size");
  PaddedBinary img(skeleton);
  internal::RecentreOnRidgeInPlace(&img, internal::RecentreSmoothing(grey, params, true), params);
  return img.ToMat();
}

namespace internal {

// Thesis 4.3.2: the two sub-iterations of eq. 4.18 - 4.20 over the live pixels,
// their conditions looked up by neighbourhood code.
void ZhangSuenThinInPlace(PaddedBinary* img, const ZhangSuenParams& params,
                          const Cancellation& cancel) {
  std::vector<size_t> live = img->SetIndices();
  std::vector<size_t> flagged;
  const CodeTable& simple = SimpleTable();
  for (int iteration = 0; iteration < params.max_iterations; ++iteration) {
    cancel.ThrowIfRequested("the thinning");
    bool changed = false;
    for (int step = 0; step < 2; ++step) {
      const CodeTable& deletable = ZhangSuenTable(step);
      flagged.clear();
      for (size_t i : live)
        if (img->data[i] && deletable[img->CodeOf(i)]) flagged.push_back(i);
      for (size_t i : flagged) {
        // Sequential re-check: keep what has become an end point or non-simple.
        if (params.preserve_topology && !simple[img->CodeOf(i)]) continue;
        img->data[i] = 0;
        changed = true;
      }
    }
    std::erase_if(live, [img](size_t i) { return !img->data[i]; });
    if (!changed) break;
  }
}

// Sweeps in raster order, deleting thinnable pixels, until a sweep deletes none.
void MakeOnePixelWideInPlace(PaddedBinary* img, TJunctionShape t_junctions,
                             const Cancellation& cancel) {
  const CodeTable& thinnable = ThinnableTable(t_junctions);
  std::vector<size_t> live = img->SetIndices();
  for (bool changed = true; changed;) {
    cancel.ThrowIfRequested("the one-pixel-wide skeleton");
    changed = false;
    for (size_t i : live) {
      if (!img->data[i] || !thinnable[img->CodeOf(i)]) continue;
      img->data[i] = 0;
      changed = true;
    }
    std::erase_if(live, [img](size_t i) { return !img->data[i]; });
  }
}

cv::Mat RecentreSmoothing(const cv::Mat& grey, const RecentreParams& params, bool in_parallel,
                          const Cancellation& cancel) {
  // The frame holds -infinity: nothing beyond the image is ever brighter.
  cv::Mat smoothed(grey.rows + 2, grey.cols + 2, CV_32F);
  const float never = -std::numeric_limits<float>::infinity();
  smoothed.row(0).setTo(never);
  smoothed.row(grey.rows + 1).setTo(never);
  smoothed.col(0).setTo(never);
  smoothed.col(grey.cols + 1).setTo(never);
  cv::Mat inner = smoothed(cv::Rect(1, 1, grey.cols, grey.rows));
  const int half = static_cast<int>(std::ceil(3.0 * params.sigma));
  // Band by band (on a ROI the filter reads the rows beyond it, so the values
  // are those of the whole image at once); once the caller asks to stop, the
  // bands left skip their work and the stage stops after.
  const auto band = [&](int y0, int y1) {
    cv::Mat rows = inner.rowRange(y0, y1);
    GaussianInto(grey.rowRange(y0, y1), params.sigma, half, &rows);
  };
  if (in_parallel) {
    ForEachBand(grey.rows, [&](int y0, int y1) {
      if (!cancel.Requested()) band(y0, y1);
    });
  } else {
    for (int y0 = 0; y0 < grey.rows && !cancel.Requested(); y0 += kBandRows)
      band(y0, std::min(grey.rows, y0 + kBandRows));
  }
  cancel.ThrowIfRequested("the smoothing for the re-centring");
  return smoothed;
}

// The passes of RecentreOnRidge on the padded buffer, pixels addressed by
// buffer index (no division per look-up).
void RecentreOnRidgeInPlace(PaddedBinary* img, const cv::Mat& smoothed,
                            const RecentreParams& params, const Cancellation& cancel) {
  const int rows = img->Rows(), cols = img->Cols();
  // Asked every kRecentrePixelsPerQuestion skeleton pixels looked at (a pass
  // over an 8 Mpx frame's skeleton takes some 40 ms on one core).
  int until_question = kRecentrePixelsPerQuestion;
  const auto ask = [&until_question, &cancel] {
    if (--until_question > 0) return;
    until_question = kRecentrePixelsPerQuestion;
    cancel.ThrowIfRequested("the re-centring on ridges");
  };
  CV_Assert(smoothed.type() == CV_32F && smoothed.rows == rows + 2 && smoothed.cols == cols + 2 &&
            smoothed.isContinuous());
  const std::ptrdiff_t stride = static_cast<std::ptrdiff_t>(img->Stride());
  // The 8 neighbours in the order dy = -1 .. 1, dx = -1 .. 1: steps and buffer offsets.
  constexpr int kDx[8] = {-1, 0, 1, -1, 1, -1, 0, 1};
  constexpr int kDy[8] = {-1, -1, -1, 0, 0, 1, 1, 1};
  std::ptrdiff_t around[8];
  for (int k = 0; k < 8; ++k) around[k] = kDy[k] * stride + kDx[k];
  auto set = [img](std::ptrdiff_t i) { return img->data[static_cast<size_t>(i)] != 0; };
  const float* f = smoothed.ptr<float>(0);
  const float min_gain = static_cast<float>(params.min_gain);
  // Near junctions the grey ridge bends towards the branches: keep clear.
  std::vector<std::uint8_t> near_junction(img->data.size(), 0);
  std::vector<size_t> pixels = img->SetIndices();  // at the start of each pass
  {
    const int c = params.junction_clearance;
    for (size_t i : pixels) {
      ask();
      if (std::popcount(img->CodeOf(i)) < 3) continue;
      const int x = img->X(i), y = img->Y(i);
      for (int yy = std::max(0, y - c); yy <= std::min(rows - 1, y + c); ++yy)
        for (int xx = std::max(0, x - c); xx <= std::min(cols - 1, x + c); ++xx)
          near_junction[img->Index(xx, yy)] = 1;
    }
  }
  std::vector<std::uint8_t> moved(img->data.size(), 0);
  std::vector<size_t> targets, kept;  // of a pass: the pixels moved to, those still set
  for (int pass = 0; pass < params.passes; ++pass) {
    for (size_t t : targets) moved[t] = 0;
    targets.clear();
    for (size_t pu : pixels) {
      ask();
      const std::ptrdiff_t p = static_cast<std::ptrdiff_t>(pu);
      if (!set(p) || moved[pu] || near_junction[pu]) continue;
      int nb[2] = {0, 0};  // neighbour numbers (into kDx, kDy, around)
      int count = 0;
      for (int k = 0; k < 8; ++k)
        if (set(p + around[k])) {
          if (count < 2) nb[count] = k;
          ++count;
        }
      if (count != 2) continue;  // ends and junctions stay
      int sx, sy;
      if (std::abs(kDy[nb[0]] - kDy[nb[1]]) == 2) {
        sx = 1, sy = 0;  // neighbours above and below: move across, along x
      } else if (std::abs(kDx[nb[0]] - kDx[nb[1]]) == 2) {
        sx = 0, sy = 1;  // neighbours left and right: move along y
      } else {
        continue;  // a corner
      }
      const float here = f[pu];
      std::ptrdiff_t best = -1;
      float best_value = here + min_gain;
      for (int sign : {-1, 1}) {
        const int dx = sign * sx, dy = sign * sy;  // p -> q
        const std::ptrdiff_t q = p + dy * stride + dx;
        // Not brighter enough (the usual case on a centred skeleton, and
        // always in the frame beyond the image): no need to look at its
        // neighbourhood.
        if (set(q) || !(f[q] >= best_value)) continue;
        bool ok = true;
        for (int k : nb) ok = ok && std::abs(kDx[k] - dx) <= 1 && std::abs(kDy[k] - dy) <= 1;
        for (std::ptrdiff_t o : around) {
          const std::ptrdiff_t r = q + o;
          if (!ok) break;
          if (r != p && r != p + around[nb[0]] && r != p + around[nb[1]] && set(r)) ok = false;
        }
        if (ok) {
          best = q;
          best_value = f[q];
        }
      }
      if (best < 0) continue;
      img->data[pu] = 0;
      img->data[static_cast<size_t>(best)] = 1;
      moved[static_cast<size_t>(best)] = 1;
      targets.push_back(static_cast<size_t>(best));
    }
    if (targets.empty()) break;
    // The next pass's pixels in raster order, as SetIndices would list them:
    // those still set, and those moved to (a pixel moved to is skipped for
    // the rest of its pass, so it stays set).
    kept.clear();
    for (size_t pu : pixels)
      if (img->data[pu]) kept.push_back(pu);
    std::sort(targets.begin(), targets.end());
    pixels.clear();
    std::set_union(kept.begin(), kept.end(), targets.begin(), targets.end(),
                   std::back_inserter(pixels));
  }
}

}  // namespace internal

}  // namespace bsls::extraction
