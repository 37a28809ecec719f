#include "bsls/interpretation/labelling.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <optional>
#include <queue>
#include <set>

#include "label_votes.h"

namespace bsls::interpretation {
namespace {

using internal::Median;
using pattern::JunctionKind;

struct Link {
  int to = -1;
  int dp = 0;
  int dv = 0;
  double weight = 1.0;
  int first_half_edge = -1;  // for vertical links: the first step taken
  bool vertical = false;
};

struct Label {
  int p = 0;
  int v = 0;
  bool operator==(const Label& o) const { return p == o.p && v == o.v; }
};

constexpr double kTrusted = 0.01;  // weight of a link inside a complete loop
constexpr double kPlain = 10.0;    // weight of any other single-row link: a path of
                                   // complete loops beats any path with one such link
constexpr int kNoLabel = std::numeric_limits<int>::min();

JunctionKind KindOf(const JunctionNetwork& net, int node) {
  return *net.role(node).attribute == JunctionAttribute::kDirect ? JunctionKind::kDirect
                                                                 : JunctionKind::kCorresponding;
}

// The kind a junction at (p, v) must have; v is relative but keeps its parity.
bool KindFits(const pattern::PatternSpec& spec, int p, int v, JunctionKind kind) {
  return pattern::JunctionOnRowParity(spec, p, v) == kind;
}

// Positioned samples bucketed by the cells of a square grid `cell` wide.
class SampleGrid {
 public:
  using Sample = std::pair<cv::Point2d, double>;

  SampleGrid(const std::vector<Sample>& samples, double cell) : samples_(samples), cell_(cell) {
    if (samples.empty()) return;
    cv::Point lo = CellOf(samples.front().first), hi = lo;
    for (const Sample& s : samples) {
      const cv::Point c = CellOf(s.first);
      lo = {std::min(lo.x, c.x), std::min(lo.y, c.y)};
      hi = {std::max(hi.x, c.x), std::max(hi.y, c.y)};
    }
    origin_ = lo;
    size_ = {hi.x - lo.x + 1, hi.y - lo.y + 1};
    cells_.resize(static_cast<size_t>(size_.area()));
    for (size_t i = 0; i < samples.size(); ++i) {
      const cv::Point c = CellOf(samples[i].first) - origin_;
      cells_[static_cast<size_t>(c.y * size_.width + c.x)].push_back(i);
    }
  }

  // Calls visit(sample) for every sample within `cell` of `at` in x and in y
  // (and some farther ones).
  template <typename Visit>
  void ForEachNear(cv::Point2d at, Visit visit) const {
    if (cells_.empty() || !std::isfinite(at.x) || !std::isfinite(at.y)) return;
    const cv::Point c = CellOf(at) - origin_;
    for (int y = std::max(c.y - 1, 0); y <= std::min(c.y + 1, size_.height - 1); ++y)
      for (int x = std::max(c.x - 1, 0); x <= std::min(c.x + 1, size_.width - 1); ++x)
        for (size_t i : cells_[static_cast<size_t>(y * size_.width + x)]) visit(samples_[i]);
  }

 private:
  cv::Point CellOf(cv::Point2d p) const {
    // Clamped far beyond any image, so that the cast is defined.
    return {static_cast<int>(std::floor(std::clamp(p.x / cell_, -1e6, 1e6))),
            static_cast<int>(std::floor(std::clamp(p.y / cell_, -1e6, 1e6)))};
  }

  const std::vector<Sample>& samples_;
  double cell_;
  cv::Point origin_;
  cv::Size size_;
  std::vector<std::vector<size_t>> cells_;
};

struct VerticalLink {
  int a = -1, b = -1;  // a above b
  int first = -1;      // half-edge leaving a downwards
  double dy = 0;
  bool alternating = false;
  bool trusted = true;
  cv::Point2d mid;
};

// Walks down the line from a pattern junction, through crossing points, to
// the next pattern junction.
bool WalkDown(const JunctionNetwork& net, const std::vector<char>& trusted_edge, int from,
              VerticalLink* link) {
  const SkeletonGraph& g = net.graph();
  int cur = from;
  link->a = from;
  link->trusted = true;
  for (int guard = 0; guard < 64; ++guard) {
    const auto step = net.AlongLine(cur, true);
    if (!step || !step->consistent) return false;
    if (link->first < 0) link->first = step->half_edge;
    link->trusted = link->trusted && trusted_edge[step->half_edge];
    const int t = step->target;
    if (net.IsPatternJunction(t)) {
      link->b = t;
      const cv::Point2d ca = net.role(from).centre, cb = net.role(t).centre;
      link->dy = cb.y - ca.y;
      link->alternating = KindOf(net, from) != KindOf(net, t);
      link->mid = (ca + cb) * 0.5;
      return link->dy > 0;
    }
    if (g.nodes()[t].kind != NodeKind::kJunction) return false;  // an end
    cur = t;  // a crossing point: the line goes straight on
  }
  return false;
}

// Pixels of a line walked from a node up or down until it stops. A line runs
// one way in y: where the chain turns back or runs sideways (into a segment,
// e.g. round the corner of a brick cut off at the image border) the walk ends.
// It also ends before a junction labelled with a line other than `line`
// (`line_of_node`: node -> p of the labelled junctions): where lines crowd
// together (a cavity's wall) the chain can cross onto a neighbour's strand,
// whose junctions know better.
std::vector<cv::Point> WalkPixels(const JunctionNetwork& net, int from, bool downwards,
                                  std::set<int>* visited_nodes,
                                  const std::map<int, int>& line_of_node, int line) {
  constexpr int kMaxSideways = 2;  // consecutive steps without progress in y
  const SkeletonGraph& g = net.graph();
  const int sign = downwards ? 1 : -1;
  std::vector<cv::Point> out;
  int extreme = cvRound(net.role(from).centre.y);
  int sideways = 0;
  auto accept = [&](const cv::Point& p) {
    if ((p.y - extreme) * sign > 0) {
      extreme = p.y;
      sideways = 0;
    } else if (p.y == extreme) {
      if (++sideways > kMaxSideways) return false;
    } else {
      return false;  // turned back
    }
    out.push_back(p);
    return true;
  };
  int cur = from;
  for (int guard = 0; guard < 10000; ++guard) {
    const auto step = net.AlongLine(cur, downwards);
    if (!step) break;
    if (const auto labelled = line_of_node.find(step->target);
        labelled != line_of_node.end() && labelled->second != line)
      break;
    for (const cv::Point& p : g.Pixels(step->half_edge))
      if (!accept(p)) return out;
    const int t = step->target;
    const cv::Point2d c = net.role(t).centre;
    if (!accept({cvRound(c.x), cvRound(c.y)})) return out;
    if (!step->consistent || !visited_nodes->insert(t).second) break;
    if (g.nodes()[t].kind == NodeKind::kEnd) break;
    cur = t;
  }
  return out;
}

// Half-edges inside complete loops, both ways: their links are trusted
// (thesis: a complete loop has its six junctions in the right order).
std::vector<char> TrustedHalfEdges(const SkeletonGraph& g, const std::vector<LoopRecord>& loops) {
  std::vector<char> trusted(g.HalfEdgeCount(), 0);
  for (const LoopRecord& loop : loops)
    if (loop.cls == LoopClass::kComplete)
      for (int h : loop.walk) trusted[h] = trusted[SkeletonGraph::Twin(h)] = 1;
  return trusted;
}

// Lines: the links between consecutive pattern junctions along each line.
std::vector<VerticalLink> LinesDown(const JunctionNetwork& net, const std::vector<char>& trusted) {
  std::vector<VerticalLink> vlinks;
  for (int n = 0; n < static_cast<int>(net.graph().nodes().size()); ++n) {
    if (!net.IsPatternJunction(n)) continue;
    VerticalLink link;
    if (WalkDown(net, trusted, n, &link)) vlinks.push_back(link);
  }
  return vlinks;
}

// The row spacing near a point: the median of the line links' spacing
// samples within `radius` (alternating steps are one row, equal kinds two),
// the frame's median where fewer than three lie there. Holds a grid over
// its own samples: neither copied nor moved.
class LocalSpacing {
 public:
  LocalSpacing(const std::vector<VerticalLink>& vlinks, double radius)
      : samples_(SamplesOf(vlinks)),
        global_(GlobalMedian(samples_)),
        grid_(samples_, radius),
        radius_(radius) {}
  LocalSpacing(const LocalSpacing&) = delete;
  LocalSpacing& operator=(const LocalSpacing&) = delete;

  double At(cv::Point2d at) const {
    near_.clear();
    const double r2 = radius_ * radius_;
    grid_.ForEachNear(at, [&](const std::pair<cv::Point2d, double>& sample) {
      const cv::Point2d d = sample.first - at;
      if (d.x * d.x + d.y * d.y <= r2) near_.push_back(sample.second);
    });
    return near_.size() >= 3 ? Median(near_) : global_;
  }

 private:
  static std::vector<SampleGrid::Sample> SamplesOf(const std::vector<VerticalLink>& vlinks) {
    std::vector<SampleGrid::Sample> samples;
    for (const VerticalLink& l : vlinks)
      samples.push_back({l.mid, l.alternating ? l.dy : l.dy / 2.0});
    return samples;
  }
  static double GlobalMedian(const std::vector<SampleGrid::Sample>& samples) {
    std::vector<double> all_spacing;
    for (const SampleGrid::Sample& s : samples) all_spacing.push_back(s.second);
    return Median(all_spacing);
  }

  const std::vector<SampleGrid::Sample> samples_;
  const double global_;
  // The samples by cell of a grid spacing_radius wide, so that a query reads
  // the 3 x 3 cells around its own only: the same samples as a scan of all
  // (in another order, which the median does not see).
  const SampleGrid grid_;
  const double radius_;
  mutable std::vector<double> near_;  // scratch of At
};

// The links between junctions, both ways: each line link that spans a whole
// number of rows (weighted by its trust and its length in rows), and each
// direct junction's segment to the next line's corresponding junction.
std::vector<std::vector<Link>> LinkJunctions(const JunctionNetwork& net,
                                             const std::vector<VerticalLink>& vlinks,
                                             const std::vector<char>& trusted,
                                             const LocalSpacing& spacing) {
  const int n_nodes = static_cast<int>(net.graph().nodes().size());
  std::vector<std::vector<Link>> adj(n_nodes);
  for (const VerticalLink& l : vlinks) {
    const double s = spacing.At(l.mid);
    const internal::RowCount step = internal::NearestRowCount(l.dy, s, l.alternating, 8);
    const int best_rows = step.rows;
    if (step.miss > 0.35 * s) continue;
    const bool normal_step = best_rows <= 2;
    const double w = l.trusted ? kTrusted : (normal_step ? kPlain : kPlain * best_rows);
    adj[l.a].push_back({l.b, 0, best_rows, w, l.first, true});
    adj[l.b].push_back({l.a, 0, -best_rows, w, -1, true});
  }
  // Segments: a direct junction's segment ends on the next line's corresponding junction.
  for (int n = 0; n < n_nodes; ++n) {
    if (!net.IsPatternJunction(n) || KindOf(net, n) != JunctionKind::kDirect) continue;
    const auto step = net.AcrossSegment(n);
    if (!step || !step->consistent || !net.IsPatternJunction(step->target)) continue;
    if (KindOf(net, step->target) != JunctionKind::kCorresponding) continue;
    const double w = trusted[step->half_edge] ? kTrusted : kPlain;
    adj[n].push_back({step->target, +1, 0, w, step->half_edge, false});
    adj[step->target].push_back({n, -1, 0, w, -1, false});
  }
  return adj;
}

// Seeds: the direct junctions of line 0 in order along it; `inner` counts
// its corresponding ones (segments on its inner side).
std::vector<int> ReferenceJunctions(const JunctionNetwork& net, const ReferenceLine& reference,
                                    int* inner) {
  const SkeletonGraph& g = net.graph();
  std::vector<int> seeds;
  std::set<int> seen;
  for (const cv::Point& px : reference.pixels) {
    const int n = g.NodeAt(px);
    if (n < 0 || !seen.insert(n).second || g.nodes()[n].kind != NodeKind::kJunction) continue;
    if (!net.IsPatternJunction(n)) continue;
    if (KindOf(net, n) == JunctionKind::kDirect)
      seeds.push_back(n);
    else
      ++*inner;
  }
  return seeds;
}

// Sorts the seeds down the image and gives each its v: two rows a step,
// the steps counted from each gap at the mean of the seeds' own spacing and
// the local one.
std::vector<int> NumberSeeds(const JunctionNetwork& net, const LocalSpacing& spacing,
                             std::vector<int>* seeds) {
  std::sort(seeds->begin(), seeds->end(),
            [&](int a, int b) { return net.role(a).centre.y < net.role(b).centre.y; });
  std::vector<double> seed_gaps;
  for (size_t i = 1; i < seeds->size(); ++i)
    seed_gaps.push_back(net.role((*seeds)[i]).centre.y - net.role((*seeds)[i - 1]).centre.y);
  const double seed_spacing = Median(seed_gaps);
  std::vector<int> seed_v{0};
  for (size_t i = 1; i < seeds->size(); ++i) {
    const double local = std::max(1.0, spacing.At(net.role((*seeds)[i]).centre) * 2.0);
    const double s = seed_spacing > 0 ? 0.5 * (local + seed_spacing) : local;
    const int steps = std::max(1, static_cast<int>(std::lround(seed_gaps[i - 1] / s)));
    seed_v.push_back(seed_v.back() + 2 * steps);
  }
  return seed_v;
}

// Propagation, most trusted links first (a Dijkstra order over link
// weights): labels every node reached from the seeds through links whose
// labels fit the junctions' kinds, with its path's cost and provenance.
void Propagate(const JunctionNetwork& net, const pattern::PatternSpec& spec,
               const std::vector<std::vector<Link>>& adj, const std::vector<int>& seeds,
               const std::vector<int>& seed_v, std::vector<Label>* label, std::vector<double>* cost,
               Labelling* out) {
  const int n_nodes = static_cast<int>(adj.size());
  label->assign(n_nodes, {kNoLabel, kNoLabel});
  cost->assign(n_nodes, std::numeric_limits<double>::infinity());
  using Item = std::tuple<double, int, int, int, int>;  // cost, node, p, v, parent
  std::priority_queue<Item, std::vector<Item>, std::greater<>> queue;
  for (size_t i = 0; i < seeds.size(); ++i) {
    (*cost)[seeds[i]] = 0;
    queue.push({0.0, seeds[i], 0, seed_v[i], -1});
  }
  std::vector<char> done(n_nodes, 0);
  while (!queue.empty()) {
    const auto [c, n, p, v, parent] = queue.top();
    queue.pop();
    if (done[n]) continue;
    done[n] = 1;
    (*label)[n] = {p, v};
    out->provenance[n] = {parent, c};
    for (const Link& l : adj[n]) {
      if (done[l.to]) continue;
      const int np = p + l.dp, nv = v + l.dv;
      if (!KindFits(spec, np, nv, KindOf(net, l.to))) continue;
      const double nc = c + l.weight;
      if (nc < (*cost)[l.to]) {
        (*cost)[l.to] = nc;
        queue.push({nc, l.to, np, nv, n});
      }
    }
  }
}

// Thesis point O: the v of line 0's junction nearest the centre row, which
// becomes v = 0.
int OriginV(const JunctionNetwork& net, const std::vector<int>& seeds,
            const std::vector<Label>& label) {
  const double centre_row = (net.graph().size().height - 1) / 2.0;
  int origin_v = 0;
  double best = 1e18;
  for (int s : seeds) {
    if (label[s].p != 0) continue;
    const double d = std::abs(net.role(s).centre.y - centre_row);
    if (d < best) {
      best = d;
      origin_v = label[s].v;
    }
  }
  return origin_v;
}

// Adds every labelled node to out->junctions, v from point O; where two
// claim one label, the better supported one keeps it. Returns each label's
// place in out->junctions.
std::map<std::pair<int, int>, size_t> CollectJunctions(const JunctionNetwork& net,
                                                       const std::vector<std::vector<Link>>& adj,
                                                       const std::vector<Label>& label,
                                                       const std::vector<double>& cost,
                                                       int origin_v, Labelling* out) {
  const SkeletonGraph& g = net.graph();
  // Support of a label: links to labelled neighbours that agree with it.
  auto support = [&](int n) {
    int agree = 0;
    for (const Link& l : adj[n])
      if (label[l.to].p != kNoLabel && label[l.to] == Label{label[n].p + l.dp, label[n].v + l.dv})
        ++agree;
    return agree;
  };
  std::map<std::pair<int, int>, size_t> by_label;
  for (int n = 0; n < static_cast<int>(label.size()); ++n) {
    if (label[n].p == kNoLabel) continue;
    LabelledJunction j;
    j.node = n;
    j.position = net.role(n).centre;
    j.p = label[n].p;
    j.v = label[n].v - origin_v;
    j.kind = KindOf(net, n);
    if (net.role(n).side >= 0) j.segment = g.Pixels(net.role(n).side);
    const auto key = std::make_pair(j.p, j.v);
    const auto clash = by_label.find(key);
    if (clash != by_label.end()) {
      // Two junctions claim one label: the better supported one keeps it.
      LabelledJunction& other = out->junctions[clash->second];
      const int mine = support(n), theirs = support(other.node);
      ++out->conflicts;
      if (mine > theirs || (mine == theirs && cost[n] < cost[other.node])) other = j;
      continue;
    }
    by_label[key] = out->junctions.size();
    out->junctions.push_back(j);
  }
  return by_label;
}

// Thesis 5.1.4.6-5.1.4.7: junctions missing on a continuous line between two
// labelled ones are placed on the line at the row of their relative junction.
void InterpolateMissing(const JunctionNetwork& net, const pattern::PatternSpec& spec,
                        const LabellingParams& params, const std::vector<VerticalLink>& vlinks,
                        const std::vector<Label>& label, int origin_v,
                        std::map<std::pair<int, int>, size_t>* by_label_out, Labelling* out) {
  const SkeletonGraph& g = net.graph();
  std::map<std::pair<int, int>, size_t>& by_label = *by_label_out;
  std::vector<LabelledJunction> added;
  for (const VerticalLink& l : vlinks) {
    if (label[l.a].p == kNoLabel || label[l.b].p == kNoLabel) continue;
    const int p = label[l.a].p;
    if (label[l.b].p != p) continue;
    const int va = label[l.a].v - origin_v, vb = label[l.b].v - origin_v;
    const int step = (p == 0 || p == spec.lines - 1) ? 2 : 1;
    const int missing = (vb - va) / step - 1;
    if (missing <= 0 || missing > params.max_interpolated_run) continue;
    // The line's pixels between the two junctions.
    std::vector<cv::Point> chain;
    int cur = l.a;
    for (int guard = 0; guard < 64 && cur != l.b; ++guard) {
      const auto s = net.AlongLine(cur, true);
      if (!s) break;
      for (const cv::Point& px : g.Pixels(s->half_edge)) chain.push_back(px);
      cur = s->target;
    }
    if (chain.empty()) continue;
    const cv::Point2d pa = net.role(l.a).centre, pb = net.role(l.b).centre;
    for (int v = va + step; v < vb; v += step) {
      const JunctionKind kind =
          ((v - p) % 2 == 0) ? JunctionKind::kDirect : JunctionKind::kCorresponding;
      if (!KindFits(spec, p, v, kind) || by_label.count({p, v})) continue;
      // The segment's other line must be there: a labelled junction on it
      // within two rows.
      const int partner_p = kind == JunctionKind::kDirect ? p + 1 : p - 1;
      bool partner_line = false;
      for (int dv = -2; dv <= 2; ++dv) partner_line |= by_label.count({partner_p, v + dv}) > 0;
      if (!partner_line) continue;
      double target_y = pa.y + (pb.y - pa.y) * (v - va) / static_cast<double>(vb - va);
      const auto partner = by_label.find({partner_p, v});
      if (partner != by_label.end()) target_y = out->junctions[partner->second].position.y;
      const auto nearest = std::min_element(chain.begin(), chain.end(), [&](auto a, auto b) {
        return std::abs(a.y - target_y) < std::abs(b.y - target_y);
      });
      LabelledJunction j;
      j.position = cv::Point2d(nearest->x, nearest->y);
      j.p = p;
      j.v = v;
      j.kind = kind;
      j.interpolated = true;
      added.push_back(j);
    }
  }
  for (const LabelledJunction& j : added) {
    if (by_label.count({j.p, j.v})) continue;
    by_label[{j.p, j.v}] = out->junctions.size();
    out->junctions.push_back(j);
  }
}

// Lines: walks each labelled line up and down from its junctions into out->lines.
void WalkLabelledLines(const JunctionNetwork& net, Labelling* out) {
  std::map<int, std::vector<int>> nodes_of_line;
  std::map<int, int> line_of_node;
  for (const LabelledJunction& j : out->junctions)
    if (j.node >= 0) {
      nodes_of_line[j.p].push_back(j.node);
      line_of_node[j.node] = j.p;
    }
  for (auto& [p, nodes] : nodes_of_line) {
    std::sort(nodes.begin(), nodes.end(),
              [&](int a, int b) { return net.role(a).centre.y < net.role(b).centre.y; });
    std::set<int> visited;
    std::vector<std::vector<cv::Point>> runs;
    for (int n : nodes) {
      if (visited.count(n)) continue;
      visited.insert(n);
      std::vector<cv::Point> up = WalkPixels(net, n, false, &visited, line_of_node, p);
      std::vector<cv::Point> run(up.rbegin(), up.rend());
      const cv::Point2d c = net.role(n).centre;
      run.push_back({cvRound(c.x), cvRound(c.y)});
      std::vector<cv::Point> down = WalkPixels(net, n, true, &visited, line_of_node, p);
      run.insert(run.end(), down.begin(), down.end());
      runs.push_back(std::move(run));
    }
    std::sort(runs.begin(), runs.end(),
              [](const auto& a, const auto& b) { return a.front().y < b.front().y; });
    LabelledLine line;
    line.p = p;
    for (const auto& run : runs) line.pixels.insert(line.pixels.end(), run.begin(), run.end());
    out->lines.push_back(std::move(line));
  }
}

}  // namespace

bool LabellingParams::IsValid(std::string* error) const {
  auto fail = [error](const char* why) {
    if (error) *error = why;
    return false;
  };
  if (max_interpolated_run < 0 || max_interpolated_run > 10)
    return fail("max_interpolated_run must lie in 0..10");
  if (max_inner_fraction < 0 || max_inner_fraction > 1)
    return fail("max_inner_fraction must lie in [0, 1]");
  if (min_reference_junctions < 1) return fail("min_reference_junctions must be at least 1");
  if (spacing_radius <= 0) return fail("spacing_radius must be positive");
  return true;
}

// Thesis 5.1.4.9: labelling.
bool LabelNetwork(const JunctionNetwork& net, const std::vector<LoopRecord>& loops,
                  const ReferenceLine& reference, const pattern::PatternSpec& spec,
                  const LabellingParams& params, Labelling* out, std::string* why) {
  std::string invalid;
  if (!params.IsValid(&invalid)) throw std::invalid_argument("LabelNetwork: " + invalid);
  *out = Labelling{};

  const std::vector<char> trusted = TrustedHalfEdges(net.graph(), loops);
  const std::vector<VerticalLink> vlinks = LinesDown(net, trusted);
  const LocalSpacing spacing(vlinks, params.spacing_radius);
  const std::vector<std::vector<Link>> adj = LinkJunctions(net, vlinks, trusted, spacing);

  int inner = 0;
  std::vector<int> seeds = ReferenceJunctions(net, reference, &inner);
  out->reference_junctions = static_cast<int>(seeds.size());
  if (static_cast<int>(seeds.size()) < params.min_reference_junctions) {
    if (why) *why = "line 0 carries " + std::to_string(seeds.size()) + " junctions";
    return false;
  }
  if (inner > params.max_inner_fraction * (inner + static_cast<double>(seeds.size()))) {
    if (why)
      *why = "the traced line has " + std::to_string(inner) +
             " segments on its inner side, so it is not line 0";
    return false;
  }
  const std::vector<int> seed_v = NumberSeeds(net, spacing, &seeds);

  std::vector<Label> label;
  std::vector<double> cost;
  Propagate(net, spec, adj, seeds, seed_v, &label, &cost, out);

  // A label most of whose neighbours disagree is dropped, not guessed.
  out->conflicts += internal::DropDisagreeingLabels(
      adj,
      [&](int n) {
        return label[n].p == kNoLabel ? std::nullopt
                                      : std::optional(std::make_pair(label[n].p, label[n].v));
      },
      [&](int n) {
        label[n] = {kNoLabel, kNoLabel};
      });

  const int origin_v = OriginV(net, seeds, label);
  std::map<std::pair<int, int>, size_t> by_label =
      CollectJunctions(net, adj, label, cost, origin_v, out);
  if (params.interpolate_missing)
    InterpolateMissing(net, spec, params, vlinks, label, origin_v, &by_label, out);
  std::sort(out->junctions.begin(), out->junctions.end(),
            [](const auto& a, const auto& b) { return a.p != b.p ? a.p < b.p : a.v < b.v; });
  WalkLabelledLines(net, out);
  return true;
}

}  // namespace bsls::interpretation
