// Private to bsls::interpretation: what the two labellings (labelling.cpp
// on the skeleton graph, track_labelling.cpp on the track network) judge
// alike: the median of row-spacing samples, the rows a step along a line
// spans, and the rule that a label its neighbours disagree with is dropped
// rather than guessed (thesis 5.1.4.9).
#ifndef BSLS_INTERPRETATION_SRC_LABEL_VOTES_H_
#define BSLS_INTERPRETATION_SRC_LABEL_VOTES_H_

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>
#include <utility>
#include <vector>

namespace bsls::interpretation::internal {

// The median of `v` (the upper middle one of an even count); 0 when empty.
inline double Median(std::vector<double> v) {
  if (v.empty()) return 0.0;
  std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
  return v[v.size() / 2];
}

// How many rows a step of dy px along a line spans at `spacing` px a row:
// the whole number (odd between junctions of alternating kinds, even
// between junctions of one kind, at most max_rows) nearest to dy, and how
// far dy misses it (px).
struct RowCount {
  int rows = 0;
  double miss = 0.0;
};
inline RowCount NearestRowCount(double dy, double spacing, bool alternating, int max_rows) {
  const int first = alternating ? 1 : 2;
  RowCount best{first, std::numeric_limits<double>::infinity()};
  for (int rows = first; rows <= max_rows; rows += 2)
    if (std::abs(dy - rows * spacing) < best.miss) best = {rows, std::abs(dy - rows * spacing)};
  return best;
}

// Drops every label most of whose labelled neighbours disagree with it (two
// or more, and more than agree), in two passes; returns how many it
// dropped. adj[j] lists j's links (members to, dp, dv: the neighbour and
// the label change towards it); label_of(j) gives j's (p, v) as an
// optional pair, empty when unlabelled; unlabel(j) drops it.
template <typename Link, typename LabelOf, typename Unlabel>
int DropDisagreeingLabels(const std::vector<std::vector<Link>>& adj, LabelOf label_of,
                          Unlabel unlabel) {
  int dropped = 0;
  for (int pass = 0; pass < 2; ++pass) {
    std::vector<int> drop;
    for (int j = 0; j < static_cast<int>(adj.size()); ++j) {
      const auto mine = label_of(j);
      if (!mine) continue;
      int agree = 0, disagree = 0;
      for (const Link& l : adj[j]) {
        const auto theirs = label_of(l.to);
        if (!theirs) continue;
        const bool same =
            theirs->first == mine->first + l.dp && theirs->second == mine->second + l.dv;
        ++(same ? agree : disagree);
      }
      if (disagree >= 2 && disagree > agree) drop.push_back(j);
    }
    for (int j : drop) unlabel(j);
    dropped += static_cast<int>(drop.size());
  }
  return dropped;
}

// Consistency along the line: going down a line (junctions_on_line[t], by
// increasing y), its labelled junctions fall into runs of one p. A line may
// cross from one surface to another (the base plane beside an object) and
// its p change there, but a run between two runs of one other p would have
// the line leave its p and come back: such a run's labels are set to
// `unlabelled` in *p and *v. Returns how many were dropped.
inline int DropRunsBetweenOneP(const std::vector<std::vector<int>>& junctions_on_line,
                               std::vector<int>* p, std::vector<int>* v, int unlabelled) {
  int dropped = 0;
  for (const std::vector<int>& line : junctions_on_line) {
    std::vector<std::pair<int, std::vector<int>>> runs;  // (p, junctions), down the line
    for (int j : line) {
      if ((*p)[j] == unlabelled) continue;
      if (runs.empty() || runs.back().first != (*p)[j]) runs.push_back({(*p)[j], {}});
      runs.back().second.push_back(j);
    }
    for (size_t r = 1; r + 1 < runs.size(); ++r) {
      if (runs[r - 1].first != runs[r + 1].first) continue;
      for (int j : runs[r].second) (*p)[j] = (*v)[j] = unlabelled;
      dropped += static_cast<int>(runs[r].second.size());
    }
  }
  return dropped;
}

}  // namespace bsls::interpretation::internal

#endif  // BSLS_INTERPRETATION_SRC_LABEL_VOTES_H_
