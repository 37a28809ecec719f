#include "bsls/interpretation/track_labelling.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <map>
#include <optional>
#include <stdexcept>
#include <tuple>

#include "label_consensus.h"
#include "label_votes.h"

namespace bsls::interpretation {
namespace {

using internal::Consensus;
using internal::ConsensusLink;
using internal::LabelByConsensus;
using internal::Median;
using pattern::JunctionKind;

struct Link {
  int to = -1;
  int dp = 0;
  int dv = 0;
};

constexpr double kSmoothSpread = 1.2;       // a smooth step's row spacing against its neighbour's
constexpr double kPitchSpread = 1.4;        // and the pitch beside its two ends
constexpr double kAbruptPitchSpread = 1.7;  // pitch at a link's two ends beyond this: abrupt
constexpr double kCrowded = 0.55;           // lines closer than this times the frame's pitch crowd
constexpr double kOwnLine = 2.0;        // px: ridge points this close to a junction are its line's
constexpr int kGapHops = 4;             // tracks without a junction a gap step passes over
constexpr double kSpacingSpread = 1.6;  // a line's own row spacing lies within this factor
                                        // of the frame's
// The row spacing along a line: the dy of a step between junctions of
// alternating kinds, half of one between junctions of the same kind.
double RowSpacing(const TrackJunction& a, const TrackJunction& b) {
  const double dy = b.position.y - a.position.y;
  return a.kind != b.kind ? dy : dy / 2.0;
}

// Thesis 5.2.1: line 0. The moving column from the unlit side stops, in
// each row, on the outermost line track; a track it stops on in most of its
// rows is a candidate. Line 0 is followed from the candidate nearest the
// centre row up and down through the candidates that start (end) within
// follow_distance of where it ends (starts), as the thesis follows it
// through its gaps; its junctions must be direct but for max_inner_fraction
// of them (a stray segment's end at a fold), or it is not line 0. With
// params.reference_choice k > 0, the chain is followed from the k-th
// nearest candidate that no earlier chain took. Empty when nothing passes;
// `why` says what failed. `choices`: the chains followed, and one more where
// a candidate is left for another.
std::vector<int> ReferenceTracks(const TrackNetwork& net, pattern::Side side,
                                 const TrackLabellingParams& params, std::string* why,
                                 int* choices) {
  const int towards_p = pattern::ImageDirectionOfIncreasingP(side);
  const int n_lines = static_cast<int>(net.lines.size());
  std::vector<int> outermost(n_lines, 0);
  const int rows = static_cast<int>(net.rows.row_start.size()) - 1;
  for (int y = 0; y < rows; ++y) {
    int best = -1;
    for (int i = net.rows.row_start[y]; i < net.rows.row_start[y + 1]; ++i) {
      if (net.line_of_point[i] < 0) continue;
      // The unlit side lies opposite to increasing p.
      if (best < 0 || (net.rows.points[i].x - net.rows.points[best].x) * towards_p < 0) best = i;
    }
    if (best >= 0) ++outermost[net.line_of_point[best]];
  }
  std::vector<char> candidate(n_lines, 0);
  for (int t = 0; t < n_lines; ++t)
    candidate[t] =
        outermost[t] >= params.reference_share * static_cast<double>(net.lines[t].points.size());
  auto first = [&](int t) { return net.rows.points[net.lines[t].points.front()]; };
  auto last = [&](int t) { return net.rows.points[net.lines[t].points.back()]; };
  // The candidates by their distance from the centre row (0 covering it),
  // the longer first among equals.
  const double centre_row = (rows - 1) / 2.0;
  std::vector<std::pair<double, int>> by_miss;
  for (int t = 0; t < n_lines; ++t)
    if (candidate[t])
      by_miss.emplace_back(std::max({0.0, first(t).y - centre_row, centre_row - last(t).y}), t);
  std::sort(by_miss.begin(), by_miss.end(), [&](const auto& a, const auto& b) {
    if (a.first != b.first) return a.first < b.first;
    if (net.lines[a.second].points.size() != net.lines[b.second].points.size())
      return net.lines[a.second].points.size() > net.lines[b.second].points.size();
    return a.second < b.second;
  });
  // The chain through `start`: followed down, then up, through candidates
  // no chain has taken.
  std::vector<char> taken(n_lines, 0);
  auto follow = [&](int start) {
    std::vector<int> chain{start};
    taken[start] = 1;
    for (const bool down : {true, false}) {
      for (int cur = start;;) {
        int next = -1;
        double next_d = 0;
        for (int t = 0; t < n_lines; ++t) {
          if (!candidate[t] || taken[t]) continue;
          const extraction::RidgePoint from = down ? last(cur) : first(cur);
          const extraction::RidgePoint to = down ? first(t) : last(t);
          const int dy = down ? to.y - from.y : from.y - to.y;
          if (dy < 1) continue;
          const double d = std::hypot(to.x - from.x, static_cast<double>(dy));
          if (d > params.follow_distance) continue;
          if (next < 0 || d < next_d) {
            next = t;
            next_d = d;
          }
        }
        if (next < 0) break;
        taken[next] = 1;
        chain.push_back(next);
        cur = next;
      }
    }
    return chain;
  };
  // Chains are followed only up to the one asked for; `choices` counts
  // them, and one more where a candidate is left over.
  std::vector<int> chain;
  int followed = 0;
  auto next = by_miss.begin();
  for (; next != by_miss.end() && followed <= params.reference_choice; ++next) {
    if (taken[next->second]) continue;
    std::vector<int> c = follow(next->second);
    if (followed++ == params.reference_choice) chain = std::move(c);
  }
  const bool more =
      std::any_of(next, by_miss.end(), [&](const auto& m) { return !taken[m.second]; });
  *choices = followed + (more ? 1 : 0);
  if (followed == 0) {
    *why = "no reference line (line 0) found";
    return {};
  }
  if (chain.empty()) {
    *why = "no reference line (line 0): no candidate " + std::to_string(params.reference_choice);
    return {};
  }
  int direct = 0, corresponding = 0;
  for (int t : chain)
    for (int j : net.junctions_on_line[t])
      ++(net.junctions[j].kind == JunctionKind::kDirect ? direct : corresponding);
  if (direct < params.min_reference_junctions) {
    *why = "no reference line (line 0): the outermost line carries " + std::to_string(direct) +
           " junctions";
    return {};
  }
  if (corresponding > params.max_inner_fraction * (direct + corresponding)) {
    *why = "no reference line (line 0): the outermost line has " + std::to_string(corresponding) +
           " segments on its inner side";
    return {};
  }
  return chain;
}

// Row spacing: each line's own where it has enough steps, else the
// frame's. A stray junction splits a step in two shorter ones, so a line's
// own spacing is the median of its steps within kSpacingSpread of the
// frame's (the median of all steps).
struct RowSpacings {
  double frame = 0;         // px a row: the median over the frame
  std::vector<double> own;  // per line track: its own, or 0 where it has too few steps

  // The spacing a line track's steps are judged by.
  double Of(int track) const { return own[track] > 0 ? own[track] : frame; }
};

// Measures the row spacings; line 0's steps are taken between its direct
// junctions only (`is_reference`: per line track, part of line 0).
RowSpacings MeasureRowSpacings(const TrackNetwork& net, const std::vector<char>& is_reference,
                               const TrackLabellingParams& params) {
  std::vector<std::vector<double>> samples(net.lines.size());
  std::vector<double> all_spacing;
  for (size_t t = 0; t < net.lines.size(); ++t) {
    int previous = -1;
    for (int j : net.junctions_on_line[t]) {
      if (is_reference[t] && net.junctions[j].kind != JunctionKind::kDirect) continue;
      if (previous >= 0)
        samples[t].push_back(RowSpacing(net.junctions[previous], net.junctions[j]));
      previous = j;
    }
    all_spacing.insert(all_spacing.end(), samples[t].begin(), samples[t].end());
  }
  RowSpacings out;
  out.frame = Median(all_spacing);
  const double frame_spacing = out.frame;
  out.own.assign(net.lines.size(), 0.0);
  for (size_t t = 0; t < net.lines.size(); ++t) {
    std::erase_if(samples[t], [&](double s) {
      return !(s >= frame_spacing / kSpacingSpread && s <= frame_spacing * kSpacingSpread);
    });
    if (static_cast<int>(samples[t].size()) >= params.min_own_spacings)
      out.own[t] = Median(samples[t]);
  }
  return out;
}

// The rows from junction a down to junction b on one line at `spacing` px
// a row; nullopt where the step fits no whole number of rows of its
// parity: it joins a false junction (a segment's end on the wrong line).
std::optional<int> RowsBetween(const TrackNetwork& net, int a, int b, double spacing,
                               const TrackLabellingParams& params) {
  if (!(spacing > 0)) return std::nullopt;
  const TrackJunction& ja = net.junctions[a];
  const TrackJunction& jb = net.junctions[b];
  const internal::RowCount step = internal::NearestRowCount(jb.position.y - ja.position.y, spacing,
                                                            ja.kind != jb.kind, params.max_rows);
  if (step.miss > params.max_row_miss * spacing) return std::nullopt;
  return step.rows;
}

// A step along a line: to the next junction down its line track, a whole
// number of rows below (to < 0: none).
struct Step {
  int to = -1;
  int rows = 0;
};

// Per junction, its step down its line track: consecutive junctions of a
// track, a whole number of rows apart.
std::vector<Step> StepsDown(const TrackNetwork& net, const RowSpacings& spacing,
                            const TrackLabellingParams& params) {
  std::vector<Step> down(net.junctions.size());
  for (size_t t = 0; t < net.lines.size(); ++t) {
    const std::vector<int>& on = net.junctions_on_line[t];
    const double s = spacing.Of(static_cast<int>(t));
    for (size_t i = 1; i < on.size(); ++i)
      if (const auto rows = RowsBetween(net, on[i - 1], on[i], s, params))
        down[on[i - 1]] = {on[i], *rows};
  }
  return down;
}

// Segments: a direct junction at one end and a corresponding one at the
// other join lines p and p + 1. Per junction: for a direct one, its
// segment's corresponding end; -1 otherwise.
std::vector<int> SegmentPartners(const TrackNetwork& net) {
  const int n = static_cast<int>(net.junctions.size());
  std::vector<int> across(n, -1);
  // Per segment track: its (direct, corresponding) junctions.
  std::vector<std::pair<int, int>> ends(net.segments.size(), {-1, -1});
  for (int j = 0; j < n; ++j) {
    auto& e = ends[net.junctions[j].segment];
    (net.junctions[j].kind == JunctionKind::kDirect ? e.first : e.second) = j;
  }
  for (const auto& [direct, corresponding] : ends)
    if (direct >= 0 && corresponding >= 0) across[direct] = corresponding;
  return across;
}

// Per junction: whether its step down / its segment is a link of a closed brick.
struct TrustedLinks {
  std::vector<char> down;
  std::vector<char> across;
};

// Thesis 5.1.4.1: a complete loop. The brick below segment A-B (A direct
// on line p, B corresponding on p + 1) closes when both lines run down
// exactly two rows, through their median junctions, to the ends of one
// segment; its six links are trusted. A brick whose top or bottom segment
// is abrupt (the line pitch jumps across it) is not, unless
// TrackLabellingParams::close_abrupt_bricks: its loop may close over lines
// crowded on a surface seen edge-on, where the line beyond is not the next.
template <typename Abrupt>
TrustedLinks TrustClosedBricks(const std::vector<Step>& down, const std::vector<int>& across,
                               const Abrupt& abrupt) {
  const int n = static_cast<int>(down.size());
  auto two_rows_down = [&](int j, std::vector<int>* path) {
    int rows = 0;
    for (int cur = j; rows < 2;) {
      if (down[cur].to < 0) return -1;
      rows += down[cur].rows;
      path->push_back(cur);
      cur = down[cur].to;
      if (rows == 2) return cur;
    }
    return -1;
  };
  TrustedLinks trusted{std::vector<char>(n, 0), std::vector<char>(n, 0)};
  std::vector<int> left_path, right_path;
  for (int a = 0; a < n; ++a) {
    const int b = across[a];
    if (b < 0) continue;
    left_path.clear();
    right_path.clear();
    const int a2 = two_rows_down(a, &left_path), b2 = two_rows_down(b, &right_path);
    if (a2 < 0 || b2 < 0 || across[a2] != b2) continue;
    if (abrupt(a, b) || abrupt(a2, b2)) continue;
    trusted.across[a] = trusted.across[a2] = 1;
    for (const auto* path : {&left_path, &right_path})
      for (int j : *path) trusted.down[j] = 1;
  }
  return trusted;
}

// Per junction: px to the nearest other line, the median over its row and
// the rows above and below it (one stray ridge point in a row, a stroke
// cut by the frame's edge, does not decide), or 0 where none is measured.
std::vector<double> PitchAtJunctions(const TrackNetwork& net) {
  const int n_rows = static_cast<int>(net.rows.row_start.size()) - 1;
  auto pitch_in_row = [&](const cv::Point2d& at, int y) {
    const auto row = net.rows.Row(y);
    // The row runs left to right: the nearest beyond kOwnLine on each side.
    const auto right = std::partition_point(row.begin(), row.end(),
                                            [&](const auto& r) { return r.x <= at.x + kOwnLine; });
    const auto left = std::partition_point(row.begin(), row.end(),
                                           [&](const auto& r) { return r.x < at.x - kOwnLine; });
    double nearest = 0;
    if (right != row.end()) nearest = right->x - at.x;
    if (left != row.begin() && (nearest == 0 || at.x - std::prev(left)->x < nearest))
      nearest = at.x - std::prev(left)->x;
    return nearest;
  };
  auto pitch_at = [&](int j) {
    const cv::Point2d at = net.junctions[j].position;
    const int centre = static_cast<int>(std::lround(at.y));
    std::array<double, 3> seen{};
    int count = 0;
    for (int y = std::max(centre - 1, 0); y <= std::min(centre + 1, n_rows - 1); ++y)
      if (const double v = pitch_in_row(at, y); v > 0) seen[count++] = v;
    if (count < 3) return count == 0 ? 0.0 : std::max(seen[0], seen[count - 1]);
    return std::max(std::min(seen[0], seen[1]), std::min(std::max(seen[0], seen[1]), seen[2]));
  };
  std::vector<double> pitch(net.junctions.size());
  for (int j = 0; j < static_cast<int>(pitch.size()); ++j) pitch[j] = pitch_at(j);
  return pitch;
}

bool Within(double a, double b, double spread) { return a > b / spread && a < b * spread; }

// The links between junctions, each kept twice: as LabelByConsensus reads
// them, and in both ends' adjacency for DropDisagreeingLabels.
class TrackLinks {
 public:
  TrackLinks(const TrackNetwork& net, const RowSpacings& spacing,
             const TrackLabellingParams& params)
      : net_(net),
        spacing_(spacing),
        params_(params),
        adj_(net.junctions.size()),
        pitch_(PitchAtJunctions(net)) {
    std::vector<double> measured;
    for (double v : pitch_)
      if (v > 0) measured.push_back(v);
    frame_pitch_ = measured.empty() ? 0.0 : Median(measured);
  }

  // Adds, for each junction, its step down its line track and its segment
  // (`trusted`: those of closed bricks).
  void AddStepsAndSegments(const std::vector<Step>& down, const std::vector<int>& across,
                           const TrustedLinks& trusted);
  // A line broken by a gap (net.line_below): adds the step from its last
  // junction above to its first below, a whole number of rows apart at the
  // line's spacing.
  void AddLineGaps() {
    for (size_t t = 0; t < net_.lines.size(); ++t) {
      if (net_.junctions_on_line[t].empty()) continue;
      // The next track down the line with a junction, across tracks without any.
      int b = net_.line_below[t];
      for (int hops = 0; b >= 0 && net_.junctions_on_line[b].empty() && hops < kGapHops; ++hops)
        b = net_.line_below[b];
      if (b < 0 || net_.junctions_on_line[b].empty()) continue;
      AddGapStep(net_.junctions_on_line[t].back(), net_.junctions_on_line[b].front());
    }
  }
  // Adds the step from junction a down to b across a break in their line,
  // where it spans a whole number of rows at a's line's spacing.
  void AddGapStep(int a, int b) {
    if (const auto rows = RowsBetween(net_, a, b, spacing_.Of(net_.junctions[a].line), params_))
      Add(a, b, 0, *rows, false, false, true);
  }

  const std::vector<std::vector<Link>>& adj() const { return adj_; }
  const std::vector<ConsensusLink>& links() const { return links_; }

  // A link is abrupt where the line pitch at its two ends differs beyond
  // what a smooth surface gives and one end's lines crowd (a grazing
  // surface, an occluding edge beside it).
  bool Abrupt(int a, int b) const {
    if (!(pitch_[a] > 0 && pitch_[b] > 0) || Within(pitch_[a], pitch_[b], kAbruptPitchSpread))
      return false;
    return std::min(pitch_[a], pitch_[b]) < kCrowded * frame_pitch_;
  }

 private:
  void Add(int a, int b, int dp, int dv, bool trusted, bool smooth = false, bool gap = false) {
    adj_[a].push_back({b, dp, dv});
    adj_[b].push_back({a, -dp, -dv});
    links_.push_back({a, b, dp, dv, trusted, smooth, Abrupt(a, b), gap});
  }

  const TrackNetwork& net_;
  const RowSpacings& spacing_;
  const TrackLabellingParams& params_;
  std::vector<std::vector<Link>> adj_;
  std::vector<ConsensusLink> links_;
  std::vector<double> pitch_;  // PitchAtJunctions
  double frame_pitch_ = 0.0;   // the median of the pitches measured
};

void TrackLinks::AddStepsAndSegments(const std::vector<Step>& down, const std::vector<int>& across,
                                     const TrustedLinks& trusted) {
  const int n = static_cast<int>(down.size());
  // A step is smooth where the step before or after it on its track has a
  // row spacing within kSmoothSpread of its own, and the lines beside its
  // two ends lie as far apart within kPitchSpread (an occluding edge
  // crossed by the track changes the spacing or the pitch).
  std::vector<int> up(n, -1);  // the junction whose step down reaches j
  for (int j = 0; j < n; ++j)
    if (down[j].to >= 0) up[down[j].to] = j;
  auto per_row = [&](int j) {
    return (net_.junctions[down[j].to].position.y - net_.junctions[j].position.y) / down[j].rows;
  };
  auto smooth_step = [&](int j) {
    const double s = per_row(j);
    const int k = down[j].to;
    if (!(pitch_[j] > 0 && pitch_[k] > 0 && Within(pitch_[j], pitch_[k], kPitchSpread)))
      return false;
    return (up[j] >= 0 && Within(per_row(up[j]), s, kSmoothSpread)) ||
           (down[k].to >= 0 && Within(per_row(k), s, kSmoothSpread));
  };
  for (int j = 0; j < n; ++j) {
    if (const Step st = down[j]; st.to >= 0)
      Add(j, st.to, 0, st.rows, trusted.down[j], smooth_step(j));
    if (const int c = across[j]; c >= 0) Add(j, c, +1, 0, trusted.across[j]);
  }
}

// Seeds: line 0's direct junctions in order down the image, two rows per
// step of their spacing; two closer than one step cannot both be line
// 0's junctions (a stray segment's end at a fold): neither seeds.
std::vector<int> LineZeroSeeds(const TrackNetwork& net, const std::vector<int>& reference,
                               const RowSpacings& spacing) {
  std::vector<int> seeds;
  for (int t : reference)
    for (int j : net.junctions_on_line[t])
      if (net.junctions[j].kind == JunctionKind::kDirect) seeds.push_back(j);
  std::sort(seeds.begin(), seeds.end(), [&](int a, int b) {
    return net.junctions[a].position.y < net.junctions[b].position.y;
  });
  auto steps_between = [&](int a, int b) {
    const double gap = net.junctions[b].position.y - net.junctions[a].position.y;
    const double s = spacing.Of(net.junctions[b].line);
    if (!(s > 0)) return 1;  // no spacing measured anywhere: one step each
    return static_cast<int>(std::lround(gap / (2 * s)));
  };
  std::vector<char> doubtful(seeds.size(), 0);
  for (size_t i = 1; i < seeds.size(); ++i)
    if (steps_between(seeds[i - 1], seeds[i]) < 1) doubtful[i - 1] = doubtful[i] = 1;
  std::vector<int> kept;
  for (size_t i = 0; i < seeds.size(); ++i)
    if (!doubtful[i]) kept.push_back(seeds[i]);
  return kept;
}

// Takes the consensus labels into `out`; a label outside the slide, or of
// the other kind, is not reported but counted as a conflict.
void TakeLabelsThatFit(const Consensus& consensus, const TrackNetwork& net,
                       const pattern::PatternSpec& spec, TrackLabels* out) {
  for (int j = 0; j < static_cast<int>(net.junctions.size()); ++j) {
    if (consensus.p[j] == kUnlabelled) continue;
    if (pattern::JunctionOnRowParity(spec, consensus.p[j], consensus.v[j]) !=
        net.junctions[j].kind) {
      ++out->conflicts;
      continue;
    }
    out->p[j] = consensus.p[j];
    out->v[j] = consensus.v[j];
  }
}

// Thesis point O: shifts every v so that line 0's junction nearest the
// centre row is v = 0.
void SetPointO(const TrackNetwork& net, const std::vector<int>& seeds, double centre_row,
               TrackLabels* out) {
  int origin_v = 0;
  double nearest = std::numeric_limits<double>::infinity();
  for (int s : seeds)
    if (out->p[s] == 0 && std::abs(net.junctions[s].position.y - centre_row) < nearest) {
      nearest = std::abs(net.junctions[s].position.y - centre_row);
      origin_v = out->v[s];
    }
  for (int j = 0; j < static_cast<int>(net.junctions.size()); ++j)
    if (out->v[j] != kUnlabelled) out->v[j] -= origin_v;
}

// Gives each line track the p most of its labelled junctions carry.
void LabelLineTracks(const TrackNetwork& net, TrackLabels* out) {
  for (size_t t = 0; t < net.lines.size(); ++t) {
    std::map<int, int> votes;
    for (int j : net.junctions_on_line[t])
      if (out->p[j] != kUnlabelled) ++votes[out->p[j]];
    if (votes.empty()) continue;
    out->line_p[t] = std::max_element(votes.begin(), votes.end(), [](const auto& a, const auto& b) {
                       return a.second < b.second;
                     })->first;
  }
}

// The consensus's islands into out->islands: their junctions that kept no
// label of line 0's component, and the line tracks not labelled from it
// on which most junctions are one island's, with the p most of them carry.
void KeepIslands(const TrackNetwork& net, const Consensus& consensus, TrackLabels* out) {
  out->islands.assign(consensus.islands, {});
  for (int j = 0; j < static_cast<int>(net.junctions.size()); ++j) {
    const int k = consensus.island[j];
    if (k < 0 || out->p[j] != kUnlabelled) continue;
    TrackLabels::Island& island = out->islands[k];
    island.junctions.push_back(j);
    island.p.push_back(consensus.island_p[j]);
    island.v.push_back(consensus.island_v[j]);
  }
  for (size_t t = 0; t < net.lines.size(); ++t) {
    if (out->line_p[t] >= 0) continue;
    std::map<std::pair<int, int>, int> votes;  // (island, relative p) -> junctions
    for (int j : net.junctions_on_line[t])
      if (consensus.island[j] >= 0 && out->p[j] == kUnlabelled)
        ++votes[{consensus.island[j], consensus.island_p[j]}];
    if (votes.empty()) continue;
    const auto best =
        std::max_element(votes.begin(), votes.end(),
                         [](const auto& a, const auto& b) { return a.second < b.second; });
    TrackLabels::Island& island = out->islands[best->first.first];
    island.lines.push_back(static_cast<int>(t));
    island.line_p.push_back(best->first.second);
  }
}

}  // namespace

bool TrackLabellingParams::IsValid(std::string* error) const {
  auto fail = [error](const char* why) {
    if (error) *error = why;
    return false;
  };
  if (!(reference_share > 0 && reference_share <= 1))
    return fail("reference_share must lie in (0, 1]");
  if (min_reference_junctions < 1) return fail("min_reference_junctions must be at least 1");
  if (!(max_inner_fraction >= 0 && max_inner_fraction <= 1))
    return fail("max_inner_fraction must lie in [0, 1]");
  if (!(max_row_miss > 0 && max_row_miss <= 0.5)) return fail("max_row_miss must lie in (0, 0.5]");
  if (!(follow_distance > 0)) return fail("follow_distance must be positive");
  if (max_rows < 1) return fail("max_rows must be at least 1");
  if (min_own_spacings < 1) return fail("min_own_spacings must be at least 1");
  if (min_support < 1) return fail("min_support must be at least 1");
  if (!(max_dissent >= 0 && max_dissent < 1)) return fail("max_dissent must lie in [0, 1)");
  if (min_island < 0) return fail("min_island must not be negative");
  if (reference_choice < 0) return fail("reference_choice must not be negative");
  if (min_seeded_half_votes < 1) return fail("min_seeded_half_votes must be at least 1");
  if (min_whole_links < 0) return fail("min_whole_links must not be negative");
  return true;
}

// Thesis 5.1.4.9: labelling, on the track network.
TrackLabels LabelTracks(const TrackNetwork& net, pattern::Side side,
                        const pattern::PatternSpec& spec, const TrackLabellingParams& params,
                        const Cancellation& cancel) {
  std::string invalid;
  if (!params.IsValid(&invalid)) throw std::invalid_argument("LabelTracks: " + invalid);
  const int n = static_cast<int>(net.junctions.size());
  TrackLabels out;
  out.p.assign(n, kUnlabelled);
  out.v.assign(n, kUnlabelled);
  out.line_p.assign(net.lines.size(), -1);

  // Line 0 (thesis 5.2.1): found first, since its segments all leave
  // towards p = 1: a corresponding junction on it is a stray segment's end.
  std::string why;
  out.reference = ReferenceTracks(net, side, params, &why, &out.reference_choices);
  if (out.reference.empty()) {
    out.error = why;
    return out;
  }
  cancel.ThrowIfRequested("line 0");
  std::vector<char> is_reference(net.lines.size(), 0);
  for (int t : out.reference) is_reference[t] = 1;
  const RowSpacings spacing = MeasureRowSpacings(net, is_reference, params);
  out.row_spacing = spacing.frame;
  cancel.ThrowIfRequested("the row spacings");

  // The links: steps along lines, segments, steps across a line's gap.
  const std::vector<Step> down = StepsDown(net, spacing, params);
  const std::vector<int> across = SegmentPartners(net);
  cancel.ThrowIfRequested("the steps along lines");
  TrackLinks links(net, spacing, params);
  const TrustedLinks trusted = TrustClosedBricks(down, across, [&](int a, int b) {
    return !params.close_abrupt_bricks && links.Abrupt(a, b);
  });
  cancel.ThrowIfRequested("the closed bricks");
  links.AddStepsAndSegments(down, across, trusted);
  links.AddLineGaps();
  cancel.ThrowIfRequested("the links between junctions");

  const std::vector<int> seeds = LineZeroSeeds(net, out.reference, spacing);
  if (static_cast<int>(seeds.size()) < params.min_reference_junctions) {
    out.error = "no reference line (line 0): it carries " + std::to_string(seeds.size()) +
                " junctions that number its rows";
    return out;
  }
  // Line 0 followed across a gap between two of its tracks that no bridge
  // joins (thesis 5.2.1): the rows counted from the gap's length.
  for (size_t i = 1; i < seeds.size(); ++i) {
    const int above = net.junctions[seeds[i - 1]].line, below = net.junctions[seeds[i]].line;
    if (above != below && net.line_below[above] != below) links.AddGapStep(seeds[i - 1], seeds[i]);
  }

  cancel.ThrowIfRequested("the links between junctions");
  // Labels proven by agreement (label_consensus.h): only the component of
  // line 0 is labelled, every other junction left unlabelled.
  std::vector<char> odd_kind(n);
  for (int j = 0; j < n; ++j) odd_kind[j] = net.junctions[j].kind == JunctionKind::kCorresponding;
  const Consensus consensus =
      LabelByConsensus(odd_kind, links.links(), seeds, params.min_reference_junctions,
                       {params.min_support, params.max_dissent, params.min_island,
                        params.min_seeded_half_votes, params.min_whole_links});
  cancel.ThrowIfRequested("the consensus of labels");
  if (consensus.p.empty() || std::none_of(consensus.p.begin(), consensus.p.end(),
                                          [](int p) { return p != kUnlabelled; })) {
    out.error = "no reference line (line 0): its junctions do not agree on their labels";
    return out;
  }
  TakeLabelsThatFit(consensus, net, spec, &out);
  const double centre_row = (static_cast<int>(net.rows.row_start.size()) - 2) / 2.0;
  cancel.ThrowIfRequested("the consensus of labels");

  // A label most of whose neighbours disagree is dropped, not guessed.
  out.conflicts += internal::DropDisagreeingLabels(
      links.adj(),
      [&](int j) {
        return out.p[j] == kUnlabelled ? std::nullopt
                                       : std::optional(std::make_pair(out.p[j], out.v[j]));
      },
      [&](int j) { out.p[j] = out.v[j] = kUnlabelled; });

  SetPointO(net, seeds, centre_row, &out);
  out.conflicts +=
      internal::DropRunsBetweenOneP(net.junctions_on_line, &out.p, &out.v, kUnlabelled);
  LabelLineTracks(net, &out);
  KeepIslands(net, consensus, &out);
  out.ok = true;
  return out;
}

}  // namespace bsls::interpretation
