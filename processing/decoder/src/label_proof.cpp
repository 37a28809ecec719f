#include "bsls/decoder/label_proof.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <optional>
#include <stdexcept>
#include <utility>
#include <vector>

namespace bsls::decoder {
namespace {

// A junction of geometry's: its label proven by the proof's beside it;
// refuted (the proof labels it otherwise); doubted (the proof saw it and
// left it unlabelled); unproven (the proof did not see it).
enum class Verdict { kProven, kRefuted, kDoubted, kUnproven };

constexpr double kMinBreakRows = 4.0;  // rows: a line's gap this long or longer breaks its run
constexpr double kStepMiss = 0.35;     // of a row spacing: a step along a line off whole rows
constexpr double kStepSpread = 1.2;    // a smooth step repeats the one before it within this
constexpr double kPitchSpread = 1.4;   // and the pitch beside its two ends within this
constexpr double kPitchRows = 4.0;     // rows: how far the pitch beside a junction is looked for

// The proof's junctions, labelled or not, looked up by position.
class ProofJunctions {
 public:
  struct Entry {
    cv::Point2d at;
    std::optional<std::pair<int, int>> label;  // (p, q); none where unlabelled
  };

  ProofJunctions(const DecodeResult& proof, double cell) : cell_(cell) {
    for (const DecodedJunction& j : proof.junctions) Add({j.position, std::make_pair(j.p, j.q)});
    for (const UnlabelledJunction& j : proof.unlabelled) Add({j.position, std::nullopt});
  }

  // The entry nearest to `at` within `reach` (<= the cell size), or null.
  const Entry* Nearest(cv::Point2d at, double reach) const {
    const Entry* best = nullptr;
    double best_d = reach;
    const auto [cx, cy] = CellOf(at);
    for (int dy = -1; dy <= 1; ++dy)
      for (int dx = -1; dx <= 1; ++dx) {
        const auto it = cells_.find({cx + dx, cy + dy});
        if (it == cells_.end()) continue;
        for (int k : it->second) {
          const double d = std::hypot(entries_[k].at.x - at.x, entries_[k].at.y - at.y);
          if (d <= best_d) {
            best_d = d;
            best = &entries_[k];
          }
        }
      }
    return best;
  }

 private:
  std::pair<int, int> CellOf(cv::Point2d at) const {
    return {static_cast<int>(std::floor(at.x / cell_)), static_cast<int>(std::floor(at.y / cell_))};
  }
  void Add(Entry e) {
    if (!std::isfinite(e.at.x) || !std::isfinite(e.at.y)) return;
    cells_[CellOf(e.at)].push_back(static_cast<int>(entries_.size()));
    entries_.push_back(e);
  }

  double cell_;
  std::vector<Entry> entries_;
  std::map<std::pair<int, int>, std::vector<int>> cells_;
};

// The even offset from the proof's q origin to geometry's that most
// junctions matched by position and p give, or nullopt where none match.
std::optional<int> OriginOffset(const DecodeResult& geometry, const ProofJunctions& proof,
                                double reach) {
  std::map<int, int> votes;
  for (const DecodedJunction& j : geometry.junctions) {
    const ProofJunctions::Entry* e = proof.Nearest(j.position, reach);
    if (e && e->label && e->label->first == j.p) ++votes[j.q - e->label->second];
  }
  std::optional<int> best;
  int most = 0;
  for (const auto& [offset, count] : votes)
    if (count > most && offset % 2 == 0) {
      most = count;
      best = offset;
    }
  return best;
}

// Per line p: its junctions' (y, verdict), by y.
using JunctionsOfLine = std::map<int, std::vector<std::pair<double, Verdict>>>;

// The median px per row between consecutive junctions of one line among
// `junctions`; 0 where no line has two.
double RowSpacing(const std::vector<DecodedJunction>& junctions) {
  std::map<int, std::vector<std::pair<double, int>>> by_line;  // p -> (y, q)
  std::vector<double> spacings;
  for (const DecodedJunction& j : junctions) by_line[j.p].emplace_back(j.position.y, j.q);
  for (auto& [p, line] : by_line) {
    std::sort(line.begin(), line.end());
    for (size_t k = 1; k < line.size(); ++k)
      if (line[k].second != line[k - 1].second)
        spacings.push_back((line[k].first - line[k - 1].first) /
                           std::abs(line[k].second - line[k - 1].second));
  }
  if (spacings.empty()) return 0.0;
  std::nth_element(spacings.begin(), spacings.begin() + spacings.size() / 2, spacings.end());
  return spacings[spacings.size() / 2];
}

// Whether `line` runs unbroken (no two rows `break_rows` or more apart)
// from row y0 to row y1.
bool Unbroken(const DecodedLine& line, double y0, double y1, double break_rows) {
  const auto& pts = line.points;
  auto at = std::lower_bound(pts.begin(), pts.end(), y0,
                             [](const cv::Point2d& q, double y) { return q.y < y; });
  if (at == pts.end() || at->y - y0 >= break_rows) return false;
  for (; at + 1 != pts.end() && at->y < y1; ++at)
    if ((at + 1)->y - at->y >= break_rows) return false;
  return at->y >= y1 - break_rows;
}

// Geometry's junctions the proof did not see (unproven): proven where they
// lie one row step along their unbroken line from a proven junction of the
// line (q one apart, dy within kStepMiss of a row spacing), a step that
// repeats the one before it within kStepSpread, with the pitch beside its
// two ends within kPitchSpread (the track chain's smooth step, thesis
// 5.1.4.9); outward, step by step (a line's last rows beyond the proof's
// reach). A junction the proof saw and did not prove as labelled (refuted,
// or left unlabelled: doubted) stops the walk; stepping into doubted ones
// put wrong labels on the base plane below a ramp.
void ProveStepsAlongLines(const DecodeResult& geometry, double spacing, double break_rows,
                          std::vector<Verdict>* verdict) {
  if (!(spacing > 0)) return;
  std::map<int, const DecodedLine*> line_of;
  for (const DecodedLine& l : geometry.lines) line_of[l.p] = &l;
  std::map<int, std::vector<int>> on_line;  // p -> junctions by y
  for (int j = 0; j < static_cast<int>(geometry.junctions.size()); ++j)
    on_line[geometry.junctions[j].p].push_back(j);
  const auto& junctions = geometry.junctions;
  // px from junction j to the nearer of its neighbouring lines, or 0: in
  // the nearest row within kPitchRows that has a centre (the lines skip the
  // rows beside their junctions, and a segment's two ends share one row).
  auto pitch_at = [&](const DecodedJunction& j) {
    double nearest = 0.0;
    for (const int q : {j.p - 1, j.p + 1}) {
      const auto it = line_of.find(q);
      if (it == line_of.end()) continue;
      const auto& pts = it->second->points;
      const auto at = std::lower_bound(pts.begin(), pts.end(), j.position.y,
                                       [](const cv::Point2d& c, double v) { return c.y < v; });
      const cv::Point2d* best = nullptr;
      for (auto k = at == pts.begin() ? at : std::prev(at); k != pts.end() && k <= at; ++k)
        if (!best || std::abs(k->y - j.position.y) < std::abs(best->y - j.position.y)) best = &*k;
      if (!best || std::abs(best->y - j.position.y) > kPitchRows) continue;
      const double d = std::abs(best->x - j.position.x);
      if (nearest == 0.0 || d < nearest) nearest = d;
    }
    return nearest;
  };
  for (auto& [line_p, line_junctions] : on_line) {
    const int p = line_p;
    std::vector<int>& js = line_junctions;  // named: lambdas below take it
    const auto line = line_of.find(p);
    if (line == line_of.end()) continue;
    std::sort(js.begin(), js.end(),
              [&](int a, int b) { return junctions[a].position.y < junctions[b].position.y; });
    // The step from js[from] to js[to], after the step from js[before].
    auto smooth = [&](int before, int from, int to) {
      const DecodedJunction &a = junctions[js[before]], &b = junctions[js[from]],
                            &c = junctions[js[to]];
      const Verdict next = (*verdict)[js[to]];
      if ((*verdict)[js[before]] != Verdict::kProven || (*verdict)[js[from]] != Verdict::kProven ||
          next != Verdict::kUnproven)
        return false;
      const double dy = std::abs(c.position.y - b.position.y);
      const double dy_before = std::abs(b.position.y - a.position.y);
      const double pitch_b = pitch_at(b), pitch_c = pitch_at(c);
      if (!(pitch_b > 0 && pitch_c > 0) || pitch_c > kPitchSpread * pitch_b ||
          pitch_b > kPitchSpread * pitch_c)
        return false;  // the lines beside it crowd or part: an occluding edge, a fold
      return std::abs(c.q - b.q) == 1 && std::abs(b.q - a.q) == 1 &&
             std::abs(dy - spacing) <= kStepMiss * spacing && dy < kStepSpread * dy_before &&
             dy_before < kStepSpread * dy &&
             Unbroken(*line->second, std::min(b.position.y, c.position.y),
                      std::max(b.position.y, c.position.y), break_rows);
    };
    const int m = static_cast<int>(js.size());
    for (int k = 2; k < m; ++k)  // downwards
      if (smooth(k - 2, k - 1, k)) (*verdict)[js[k]] = Verdict::kProven;
    for (int k = m - 3; k >= 0; --k)  // upwards
      if (smooth(k + 2, k + 1, k)) (*verdict)[js[k]] = Verdict::kProven;
  }
}

// Whether a line row at y is kept: between two proven junctions of its run
// of rows, or within `tail` px of a proven one at the run's end. `on_run`:
// the junctions of the line within the run, by y.
bool KeepRow(double y, const std::vector<std::pair<double, Verdict>>& on_run, double tail) {
  const auto after = std::lower_bound(on_run.begin(), on_run.end(), y,
                                      [](const auto& j, double v) { return j.first < v; });
  const bool has_after = after != on_run.end(), has_before = after != on_run.begin();
  if (has_after && after->first == y) return after->second == Verdict::kProven;
  if (has_before && has_after)
    return std::prev(after)->second == Verdict::kProven && after->second == Verdict::kProven;
  if (has_after) return after->second == Verdict::kProven && after->first - y <= tail;
  if (has_before)
    return std::prev(after)->second == Verdict::kProven && y - std::prev(after)->first <= tail;
  return false;
}

// The rows of `line` that KeepRow keeps, run by run (a run: rows less than
// `break_rows` apart; a line skips a few rows at each junction).
std::vector<cv::Point2d> KeptRows(const DecodedLine& line,
                                  const std::vector<std::pair<double, Verdict>>& junctions,
                                  double tail, double break_rows, LabelProofReport* r) {
  std::vector<cv::Point2d> kept;
  const std::vector<cv::Point2d>& pts = line.points;
  std::vector<std::pair<double, Verdict>> on_run;
  for (size_t begin = 0; begin < pts.size();) {
    size_t end = begin + 1;
    while (end < pts.size() && pts[end].y - pts[end - 1].y < break_rows) ++end;
    on_run.clear();
    for (const auto& j : junctions)
      if (j.first >= pts[begin].y - 0.5 && j.first <= pts[end - 1].y + 0.5) on_run.push_back(j);
    for (size_t k = begin; k < end; ++k) {
      if (KeepRow(pts[k].y, on_run, tail)) {
        kept.push_back(pts[k]);
        ++r->rows_kept;
      } else {
        ++r->rows_dropped;
      }
    }
    begin = end;
  }
  return kept;
}

// The proof's labels where geometry has no proven junction beside them
// (its q moved to geometry's origin by `offset`), and the proof's line rows
// where geometry kept none of that line, into *out and *rows_of.
void AddTheProofsOwn(const DecodeResult& proof, int offset, double reach, DecodeResult* out,
                     std::map<int, std::map<int, double>>* rows_of, LabelProofReport* r) {
  DecodeResult kept;
  kept.junctions = out->junctions;
  const ProofJunctions proven(kept, reach);
  for (DecodedJunction j : proof.junctions) {
    if (proven.Nearest(j.position, reach)) continue;
    j.q += offset;
    out->junctions.push_back(j);
    ++r->added;
  }
  for (const DecodedLine& line : proof.lines) {
    std::map<int, double>& rows = (*rows_of)[line.p];
    for (const cv::Point2d& q : line.points)
      if (rows.emplace(static_cast<int>(std::lround(q.y)), q.x).second) ++r->rows_added;
  }
}

}  // namespace

bool LabelProofParams::IsValid(std::string* error) const {
  auto fail = [error](const char* why) {
    if (error) *error = why;
    return false;
  };
  if (!(reach_px > 0) || !std::isfinite(reach_px)) return fail("reach_px must be positive");
  if (!(tail_rows >= 0) || !std::isfinite(tail_rows)) return fail("tail_rows must not be negative");
  return true;
}

DecodeResult KeepProvenLabels(const DecodeResult& geometry, const DecodeResult& proof,
                              const LabelProofParams& params, LabelProofReport* report) {
  std::string why;
  if (!params.IsValid(&why)) throw std::invalid_argument("KeepProvenLabels: " + why);
  LabelProofReport r;
  if (report) *report = r;
  if (!proof.ok || !geometry.ok) return proof;
  const ProofJunctions proven_by(proof, params.reach_px);
  const std::optional<int> offset = OriginOffset(geometry, proven_by, params.reach_px);
  if (!offset) return proof;  // no label of geometry's is proven: the proof's alone

  DecodeResult out = geometry;
  out.junctions.clear();
  out.lines.clear();
  out.unlabelled = proof.unlabelled;
  out.islands = proof.islands;
  out.islands_placed = proof.islands_placed;
  out.line_zero_moved = proof.line_zero_moved;
  out.reference_choice = proof.reference_choice;
  out.ruled_out = proof.ruled_out;
  const int n = static_cast<int>(geometry.junctions.size());
  std::vector<Verdict> verdict(n, Verdict::kUnproven);
  std::vector<DecodedJunction> proven;
  for (int k = 0; k < n; ++k) {
    const DecodedJunction& j = geometry.junctions[k];
    if (const ProofJunctions::Entry* e = proven_by.Nearest(j.position, params.reach_px))
      verdict[k] = !e->label                                         ? Verdict::kDoubted
                   : *e->label == std::make_pair(j.p, j.q - *offset) ? Verdict::kProven
                                                                     : Verdict::kRefuted;
    if (verdict[k] == Verdict::kProven) proven.push_back(j);
  }
  const double spacing = RowSpacing(proven);
  const double tail = params.tail_rows * spacing;
  // A break in a line longer than half a row is no junction's skip.
  const double break_rows = std::max(kMinBreakRows, 0.5 * spacing);
  ProveStepsAlongLines(geometry, spacing, break_rows, &verdict);
  JunctionsOfLine of_line;
  for (int k = 0; k < n; ++k) {
    const DecodedJunction& j = geometry.junctions[k];
    of_line[j.p].emplace_back(j.position.y, verdict[k]);
    if (verdict[k] == Verdict::kProven) {
      out.junctions.push_back(j);
      ++r.proven;
    } else if (verdict[k] != Verdict::kUnproven) {
      ++r.refuted;  // the proof's own label or doubt stands there
    } else {
      out.unlabelled.push_back({j.position, j.kind});  // seen by geometry's chain alone
      ++r.unproven;
    }
  }
  for (auto& [p, line] : of_line) std::sort(line.begin(), line.end());
  std::map<int, std::map<int, double>> rows_of;  // p -> row -> x
  for (const DecodedLine& line : geometry.lines) {
    const auto it = of_line.find(line.p);
    if (it == of_line.end()) {
      r.rows_dropped += static_cast<int>(line.points.size());
      continue;
    }
    for (const cv::Point2d& q : KeptRows(line, it->second, tail, break_rows, &r))
      rows_of[line.p][static_cast<int>(std::lround(q.y))] = q.x;
  }
  AddTheProofsOwn(proof, *offset, params.reach_px, &out, &rows_of, &r);
  for (const auto& [p, rows] : rows_of) {
    DecodedLine& line = out.lines.emplace_back(DecodedLine{p, {}});
    for (const auto& [y, x] : rows) line.points.emplace_back(x, y);
  }
  std::sort(out.junctions.begin(), out.junctions.end(),
            [](const DecodedJunction& a, const DecodedJunction& b) {
              return a.p != b.p ? a.p < b.p : a.q < b.q;
            });
  std::sort(out.unlabelled.begin(), out.unlabelled.end(),
            [](const UnlabelledJunction& a, const UnlabelledJunction& b) {
              return a.position.y < b.position.y;
            });
  if (report) *report = r;
  return out;
}

}  // namespace bsls::decoder
