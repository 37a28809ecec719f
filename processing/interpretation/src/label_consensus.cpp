#include "label_consensus.h"

#include <algorithm>
#include <climits>
#include <map>
#include <numeric>
#include <optional>
#include <tuple>
#include <utility>

namespace bsls::interpretation::internal {
namespace {

constexpr int kNone = INT_MIN;  // kUnlabelled of track_labelling.h
// Rounds of dropping contradicting trusted links before a patch that still
// contradicts itself loses all of them (each round drops at least one).
constexpr int kPatchRounds = 16;

struct Label {
  int p = 0;
  int v = 0;
  Label operator+(const Label& o) const { return {p + o.p, v + o.v}; }
  Label operator-(const Label& o) const { return {p - o.p, v - o.v}; }
  bool operator==(const Label& o) const = default;
  auto operator<=>(const Label& o) const = default;
};

bool OddSum(const Label& l) { return ((l.p + l.v) % 2 + 2) % 2 == 1; }

// Patches: the junctions joined by trusted links, each labelled relative to
// its first junction. A trusted link its patch contradicts is dropped with
// every other trusted link of its two ends (which of them is wrong cannot
// be told, so both junctions must be proven again as lone ones), and the
// patches are made again.
struct Patches {
  std::vector<int> of;     // per junction: its patch
  std::vector<Label> rel;  // per junction: its label within its patch
  int count = 0;
};

Patches MakePatches(const std::vector<char>& odd_kind, const std::vector<ConsensusLink>& links,
                    std::vector<char>* trusted, int* contradicted) {
  const int n = static_cast<int>(odd_kind.size());
  Patches out;
  for (int round = 0;; ++round) {
    std::vector<std::vector<std::pair<int, int>>> adj(n);  // (link, +1 forwards / -1 backwards)
    for (int k = 0; k < static_cast<int>(links.size()); ++k)
      if ((*trusted)[k]) {
        adj[links[k].a].emplace_back(k, +1);
        adj[links[k].b].emplace_back(k, -1);
      }
    out.of.assign(n, -1);
    out.rel.assign(n, {});
    out.count = 0;
    std::vector<int> queue;
    for (int root = 0; root < n; ++root) {
      if (out.of[root] >= 0) continue;
      out.of[root] = out.count;
      out.rel[root] = {0, odd_kind[root] ? 1 : 0};
      queue.assign(1, root);
      for (size_t i = 0; i < queue.size(); ++i) {
        const int j = queue[i];
        for (const auto& [k, dir] : adj[j]) {
          const ConsensusLink& l = links[k];
          const int to = dir > 0 ? l.b : l.a;
          if (out.of[to] >= 0) continue;
          out.of[to] = out.count;
          out.rel[to] = out.rel[j] + Label{dir * l.dp, dir * l.dv};
          queue.push_back(to);
        }
      }
      ++out.count;
    }
    // Contradictions: a trusted link whose ends' labels differ from its
    // change, or that gives a junction a label of the other kind.
    std::vector<int> bad;
    for (int k = 0; k < static_cast<int>(links.size()); ++k) {
      if (!(*trusted)[k]) continue;
      const ConsensusLink& l = links[k];
      const Label want = out.rel[l.a] + Label{l.dp, l.dv};
      if (!(want == out.rel[l.b]) || OddSum(want) != static_cast<bool>(odd_kind[l.b]))
        bad.push_back(k);
    }
    if (bad.empty()) return out;
    if (round + 1 >= kPatchRounds) {
      // Still contradicting: every trusted link of those patches goes.
      std::vector<char> doubtful(out.count, 0);
      for (int k : bad) doubtful[out.of[links[k].a]] = 1;
      for (int k = 0; k < static_cast<int>(links.size()); ++k)
        if ((*trusted)[k] && doubtful[out.of[links[k].a]]) bad.push_back(k);
    }
    std::vector<char> doubted(n, 0);
    for (int k : bad) {
      *contradicted += (*trusted)[k] ? 1 : 0;
      doubted[links[k].a] = doubted[links[k].b] = 1;
    }
    for (int k = 0; k < static_cast<int>(links.size()); ++k)
      if (doubted[links[k].a] || doubted[links[k].b]) (*trusted)[k] = 0;
  }
}

// Components of patches joined with a shift: a label in a patch's own frame
// plus the shift found here is its label in its component's frame.
class Components {
 public:
  // One component per patch; sizes[x]: patch x's junctions.
  explicit Components(std::vector<int> sizes)
      : parent_(sizes.size()), shift_(sizes.size()), size_(std::move(sizes)) {
    std::iota(parent_.begin(), parent_.end(), 0);
  }

  // The component of patch x, and the shift from x's frame to its frame.
  std::pair<int, Label> Find(int x) {
    Label total{};
    int r = x;
    while (parent_[r] != r) {
      total = total + shift_[r];
      r = parent_[r];
    }
    // Path compression: every patch on the way points at r directly.
    Label rest = total;
    for (int y = x; parent_[y] != y;) {
      const int next = parent_[y];
      const Label own = shift_[y];
      parent_[y] = r;
      shift_[y] = rest;
      rest = rest - own;
      y = next;
    }
    return {r, total};
  }

  // Joins the components of x and y so that a label in y's frame plus h is
  // its label in x's frame.
  void Join(int x, int y, Label h) {
    auto [rx, sx] = Find(x);
    auto [ry, sy] = Find(y);
    if (rx == ry) return;
    // ry's frame -> y's frame (-sy) -> x's frame (+h) -> rx's frame (+sx).
    Label ry_to_rx = sx + h - sy;
    if (size_[ry] > size_[rx]) {
      std::swap(rx, ry);
      ry_to_rx = Label{} - ry_to_rx;
    }
    parent_[ry] = rx;
    shift_[ry] = ry_to_rx;
    size_[rx] += size_[ry];
  }

 private:
  std::vector<int> parent_;
  std::vector<Label> shift_;  // to the parent's frame
  std::vector<int> size_;     // junctions, at a component's root
};

// Junctions in no closed brick (a patch of their own) at the pattern's
// edges (the last row of bricks, a line's end at the outline) join the
// labelled ones when two of their links agree: a link to a labelled
// junction is one vote, a link to another lone junction is one vote for
// what that junction's own links to labelled ones agree on. Two votes
// through different links close a cycle whose labels agree; one vote
// through a smooth step along its line (ConsensusLink::smooth) is enough
// where no other link disagrees. Rounds until
// none is added; each round adds all it finds at once, so the order of the
// junctions does not matter.
void AttachLoneJunctions(const std::vector<char>& odd_kind, const std::vector<ConsensusLink>& links,
                         const std::vector<int>& patch_of, const std::vector<int>& patch_size,
                         const ConsensusParams& params, std::vector<char>* labelled,
                         std::vector<Label>* label) {
  const int n = static_cast<int>(odd_kind.size());
  struct Arc {
    int to;
    Label d;  // label change towards `to`
    bool smooth;
    bool abrupt;
  };
  std::vector<std::vector<Arc>> adj(n);
  for (const ConsensusLink& l : links) {
    adj[l.a].push_back({l.b, {l.dp, l.dv}, l.smooth, l.abrupt});
    adj[l.b].push_back({l.a, {-l.dp, -l.dv}, l.smooth, l.abrupt});
  }
  auto lone = [&](int j) { return !(*labelled)[j] && patch_size[patch_of[j]] == 1; };
  // What the labelled neighbours of lone junction m agree on for m itself.
  auto own_label = [&](int m) -> std::optional<Label> {
    std::optional<Label> agreed;
    for (const auto& [k, d, smooth, abrupt] : adj[m]) {
      if (!(*labelled)[k]) continue;
      const Label here = (*label)[k] - d;
      if (agreed && !(*agreed == here)) return std::nullopt;
      agreed = here;
    }
    return agreed;
  };
  std::vector<std::pair<int, Label>> found;
  std::map<Label, int> votes;
  for (bool added = true; added;) {
    found.clear();
    for (int j = 0; j < n; ++j) {
      if (!lone(j)) continue;
      votes.clear();
      int total = 0;
      bool smooth_vote = false;
      for (const auto& [k, d, smooth, abrupt] : adj[j]) {
        std::optional<Label> via;
        if ((*labelled)[k])
          via = (*label)[k];
        else if (lone(k))
          via = own_label(k);
        if (!via) continue;
        // In half votes: a link whose ends' pitch differs abruptly is half a vote.
        const int weight = abrupt ? 1 : 2;
        votes[*via - d] += weight;
        total += weight;
        smooth_vote = smooth_vote || (smooth && !abrupt && (*labelled)[k]);
      }
      int best = 0;
      Label best_label{};
      for (const auto& [l, count] : votes)
        if (count > best && OddSum(l) == static_cast<bool>(odd_kind[j])) {
          best = count;
          best_label = l;
        }
      if ((best >= 2 * params.min_support && total - best <= params.max_dissent * best) ||
          (best == 2 && total == 2 && smooth_vote))
        found.emplace_back(j, best_label);
    }
    for (const auto& [j, l] : found) {
      (*labelled)[j] = 1;
      (*label)[j] = l;
    }
    added = !found.empty();
  }
}

// Line 0 broken into parts that no two links join (the nose's tip, a lump
// below it): a component whose own seeds agree on its p joins line 0's
// main one through the links between them whose shift of p the two sets of
// seeds confirm, where those agree on one shift (v) and no link
// contradicts them. The seeds are the second, independent witness that a
// single link lacks, but for p only: the rows (v) rest on the links alone,
// so they must carry params.min_seeded_half_votes (a step across a line's
// gap, whose rows an occluding edge may shift, is one; a whole link two).
// `votes`: (component, p shift) -> seeds.
// Returns whether it joined any; components joined to the main one
// through another seeded one take rounds.
template <typename LabelOf>
bool JoinSeededComponents(const std::vector<ConsensusLink>& links, const std::vector<char>& trusted,
                          const std::map<std::pair<int, int>, int>& votes, int main_c,
                          int main_shift, int min_seeds, const ConsensusParams& params,
                          LabelOf label_of, Components* comps) {
  bool joined = false;
  std::map<int, std::pair<int, int>> best;  // component -> (p shift, seeds)
  std::map<int, int> total;                 // component -> seeds
  for (const auto& [key, count] : votes) {
    total[key.first] += count;
    auto& b = best[key.first];
    if (count > b.second) b = {key.second, count};
  }
  for (const auto& [c, b] : best) {
    if (c == main_c || b.second < min_seeds || total[c] - b.second > params.max_dissent * b.second)
      continue;
    // Shifts from c's frame to the main one's root frame that the links give.
    const auto [root, root_shift] = comps->Find(main_c);
    if (comps->Find(c).first != c || c == root) continue;  // joined already
    std::map<Label, int> shifts;
    int against = 0, count = 0;
    int half_votes = 0;  // of the links giving a possible shift
    for (size_t k = 0; k < links.size(); ++k) {
      if (trusted[k]) continue;
      const ConsensusLink& l = links[k];
      const auto [ca, la] = label_of(l.a);
      const auto [cb, lb] = label_of(l.b);
      Label h;
      if (ca == root && cb == c)
        h = la + Label{l.dp, l.dv} - lb;
      else if (ca == c && cb == root)
        h = lb - Label{l.dp, l.dv} - la;
      else
        continue;
      ++count;
      // c's p is its own label plus b.first; through the link, plus h.p
      // back to main_c's frame and its shift.
      if (h.p - root_shift.p + main_shift != b.first || OddSum(h)) {
        ++against;
      } else {
        ++shifts[h];
        half_votes += l.gap ? 1 : 2;
      }
    }
    if (shifts.size() != 1 || half_votes < params.min_seeded_half_votes) continue;
    const auto& [h, agree] = *shifts.begin();
    if (count - agree > params.max_dissent * agree || against > 0) continue;
    comps->Join(root, c, h);
    joined = true;
  }
  return joined;
}

// One untrusted link between two components as they stand: the shift from
// y's frame to x's (x < y), worth w half votes.
struct Evidence {
  int x, y;
  Label h;
  int w;  // half votes
};

// The evidence of the untrusted links between components, sorted by (x, y,
// h), into `evidence` (reused from round to round).
template <typename LabelOf>
void GatherEvidence(const std::vector<ConsensusLink>& links, const std::vector<char>& trusted,
                    LabelOf label_of, std::vector<Evidence>* evidence) {
  evidence->clear();
  for (size_t k = 0; k < links.size(); ++k) {
    if (trusted[k]) continue;
    // In half votes: a step across a break in a line (its rows counted
    // over the gap, where an occluding edge may shift them) is half a vote.
    const int w = links[k].gap ? 1 : 2;
    const ConsensusLink& l = links[k];
    auto [ca, la] = label_of(l.a);
    auto [cb, lb] = label_of(l.b);
    if (ca == cb) continue;
    // b's label in a's frame is la + d: the shift from b's frame to a's.
    Label h = la + Label{l.dp, l.dv} - lb;
    if (ca > cb) {
      std::swap(ca, cb);
      h = Label{} - h;
    }
    evidence->push_back({ca, cb, h, w});
  }
  std::sort(evidence->begin(), evidence->end(), [](const Evidence& a, const Evidence& b) {
    return std::tie(a.x, a.y, a.h) < std::tie(b.x, b.y, b.h);
  });
}

// A join two components' evidence agrees on.
struct Candidate {
  int support, x, y;
  Label h;
};

// Per pair of components in the sorted `evidence`, the shift most of it
// gives, where that has min_support votes, min_whole_links of them whole
// (not steps across a gap), and little dissent; the best supported first.
std::vector<Candidate> AgreedJoins(const std::vector<Evidence>& evidence,
                                   const ConsensusParams& params) {
  std::vector<Candidate> candidates;
  for (size_t i = 0; i < evidence.size();) {
    size_t end = i;
    int best = 0, total = 0, best_whole = 0;
    Label best_h{};
    while (end < evidence.size() && evidence[end].x == evidence[i].x &&
           evidence[end].y == evidence[i].y) {
      size_t run = end;
      int count = 0, whole = 0;
      while (run < evidence.size() && evidence[run].x == evidence[end].x &&
             evidence[run].y == evidence[end].y && evidence[run].h == evidence[end].h) {
        whole += evidence[run].w == 2 ? 1 : 0;
        count += evidence[run++].w;
      }
      total += count;
      // A shift that changes the parity of p + v is impossible: dissent.
      if (!OddSum(evidence[end].h) && count > best) {
        best = count;
        best_h = evidence[end].h;
        best_whole = whole;
      }
      end = run;
    }
    const int dissent = total - best;
    if (best >= 2 * params.min_support && dissent <= params.max_dissent * best &&
        best_whole >= params.min_whole_links)
      candidates.push_back({best, evidence[i].x, evidence[i].y, best_h});
    i = end;
  }
  std::sort(candidates.begin(), candidates.end(),
            [&](const Candidate& a, const Candidate& b) { return a.support > b.support; });
  return candidates;
}

// Rounds of joining: the evidence between the components as they stand,
// the best supported joins first; again while any join was made.
template <typename LabelOf>
void JoinAgreeingComponents(const std::vector<ConsensusLink>& links,
                            const std::vector<char>& trusted, const ConsensusParams& params,
                            LabelOf label_of, Components* comps) {
  std::vector<Evidence> evidence;
  for (bool joined = true; joined;) {
    joined = false;
    GatherEvidence(links, trusted, label_of, &evidence);
    for (const Candidate& c : AgreedJoins(evidence, params)) {
      if (comps->Find(c.x).first == comps->Find(c.y).first) continue;
      comps->Join(c.x, c.y, c.h);
      joined = true;
    }
  }
}

// What line 0's seeds say of the components: the (component, p shift) most
// of them give, and how many give another shift in that component.
struct LineZeroVote {
  std::map<std::pair<int, int>, int> votes;  // (component, p shift) -> seeds
  int component = -1;                        // -1: no seeds
  int shift = 0;
  int seeds = 0;
  int dissent = 0;
};

// Line 0: each seed says its component's p is shifted by minus its p there.
template <typename LabelOf>
LineZeroVote VoteLineZero(const std::vector<int>& seeds, LabelOf label_of) {
  LineZeroVote out;
  for (int s : seeds) {
    const auto [c, l] = label_of(s);
    ++out.votes[{c, -l.p}];
  }
  std::map<int, int> seeds_of;  // component -> seeds
  for (const auto& [key, count] : out.votes) seeds_of[key.first] += count;
  for (const auto& [key, count] : out.votes)
    if (count > out.seeds) {
      out.seeds = count;
      out.component = key.first;
      out.shift = key.second;
    }
  if (out.component >= 0) out.dissent = seeds_of[out.component] - out.seeds;
  return out;
}

// The components of at least `min_island` junctions that hold none of
// the `labelled` ones, each labelled in its own frame, into out's island
// fields.
template <typename LabelOf>
void KeepIslands(const std::vector<char>& labelled, LabelOf label_of, int min_island,
                 Consensus* out) {
  const int n = static_cast<int>(labelled.size());
  out->island.assign(n, -1);
  out->island_p.assign(n, kNone);
  out->island_v.assign(n, kNone);
  if (min_island <= 0) return;
  std::map<int, int> size;  // component root -> junctions; -1 marks one touching line 0's
  for (int j = 0; j < n; ++j) {
    const int c = label_of(j).first;
    if (labelled[j])
      size[c] = -1;
    else if (size[c] >= 0)
      ++size[c];
  }
  std::map<int, int> index;
  for (const auto& [c, count] : size)
    if (count >= min_island) index[c] = out->islands++;
  for (int j = 0; j < n; ++j) {
    const auto [c, l] = label_of(j);
    const auto it = index.find(c);
    if (it == index.end()) continue;
    out->island[j] = it->second;
    out->island_p[j] = l.p;
    out->island_v[j] = l.v;
  }
}

// Whether a whole link (neither abrupt nor across a gap) from a labelled
// junction places a seed left unlabelled beyond line 0 (p < 0): a junction
// the reference line claims as line 0 and the labels as the line before
// it. Where line 0 hides behind an occluding edge over part of its length
// (a profile turned away), the outermost lit line there is line 1 and the
// reference line runs on it; the labels then count from line 1.
bool SeedPlacedBeyondLineZero(const std::vector<ConsensusLink>& links,
                              const std::vector<int>& seeds, const std::vector<char>& labelled,
                              const std::vector<Label>& label) {
  std::vector<char> is_seed(labelled.size(), 0);
  for (int s : seeds) is_seed[s] = 1;
  return std::any_of(links.begin(), links.end(), [&](const ConsensusLink& l) {
    if (l.abrupt || l.gap) return false;
    return (is_seed[l.a] && !labelled[l.a] && labelled[l.b] && label[l.b].p - l.dp < 0) ||
           (is_seed[l.b] && !labelled[l.b] && labelled[l.a] && label[l.a].p + l.dp < 0);
  });
}

}  // namespace

Consensus LabelByConsensus(const std::vector<char>& odd_kind,
                           const std::vector<ConsensusLink>& links, const std::vector<int>& seeds,
                           int min_seeds, const ConsensusParams& params) {
  const int n = static_cast<int>(odd_kind.size());
  Consensus out;
  out.p.assign(n, kNone);
  out.v.assign(n, kNone);
  std::vector<char> trusted(links.size());
  for (size_t k = 0; k < links.size(); ++k) trusted[k] = links[k].trusted;
  const Patches patches = MakePatches(odd_kind, links, &trusted, &out.contradicted_links);

  // Sizes in junctions, so that the larger component keeps its frame.
  std::vector<int> sizes(patches.count, 0);
  for (int j = 0; j < n; ++j) ++sizes[patches.of[j]];
  Components comps(std::move(sizes));
  auto label_of = [&](int j) {
    const auto [c, shift] = comps.Find(patches.of[j]);
    return std::make_pair(c, patches.rel[j] + shift);
  };
  JoinAgreeingComponents(links, trusted, params, label_of, &comps);

  // The seeds of the chosen component must agree: those that do not are
  // stray junctions beside line 0, and may not outnumber a third of them.
  const LineZeroVote zero = VoteLineZero(seeds, label_of);
  if (zero.component < 0 || zero.seeds < min_seeds ||
      zero.dissent > params.max_dissent * zero.seeds)
    return out;
  const Label shift{zero.shift, (zero.shift % 2 + 2) % 2};  // keeps p + v's parity
  // The seeds' votes name components as they stood; a component joined
  // since answers to its root.
  while (JoinSeededComponents(links, trusted, zero.votes, zero.component, zero.shift, min_seeds,
                              params, label_of, &comps)) {
  }
  // Labels in the frame of line 0's component as it now stands: its root
  // may have moved with a join, so they are taken back to the frame of the
  // component the seeds chose.
  const auto [main_root, main_shift] = comps.Find(zero.component);
  std::vector<char> labelled(n, 0);
  std::vector<Label> label(n);
  for (int j = 0; j < n; ++j) {
    const auto [c, l] = label_of(j);
    if (c != main_root) continue;
    labelled[j] = 1;
    label[j] = l - main_shift + shift;
  }
  std::vector<int> patch_size(patches.count, 0);
  for (int j = 0; j < n; ++j) ++patch_size[patches.of[j]];
  AttachLoneJunctions(odd_kind, links, patches.of, patch_size, params, &labelled, &label);
  if (SeedPlacedBeyondLineZero(links, seeds, labelled, label)) return out;
  for (int j = 0; j < n; ++j)
    if (labelled[j]) {
      out.p[j] = label[j].p;
      out.v[j] = label[j].v;
    }
  KeepIslands(labelled, label_of, params.min_island, &out);
  return out;
}

}  // namespace bsls::interpretation::internal
