#include "bsls/interpretation/skeleton_graph.h"

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <functional>
#include <numeric>
#include <opencv2/imgproc.hpp>
#include <set>
#include <stdexcept>
#include <utility>

#include "bsls/interpretation/chain_code.h"

namespace bsls::interpretation {
namespace {

constexpr int kNone = -1;

bool Inside(const cv::Mat& m, int x, int y) { return x >= 0 && y >= 0 && x < m.cols && y < m.rows; }

int EncodeEdge(int e) { return -e - 2; }
int DecodeEdge(int v) { return -v - 2; }

// The crossing number of a pixel: how many separate runs of set pixels its
// eight neighbours form, walked round (three or more: a branch point).
template <typename IsSet>
int CrossingNumber(cv::Point p, IsSet is_set) {
  // The neighbours in chain-code order run round the pixel.
  int runs = 0;
  bool prev = is_set(p.x + kCodeDx[7], p.y + kCodeDy[7]);
  for (int k = 0; k < 8; ++k) {
    const bool cur = is_set(p.x + kCodeDx[k], p.y + kCodeDy[k]);
    if (cur && !prev) ++runs;
    prev = cur;
  }
  return runs;
}

// Splits a junction cluster that is two T-junctions joined by a short
// segment: its branch pixels form exactly two 8-connected groups at least 3 px
// apart, more side by side than one above the other. Every pixel of the
// cluster goes to the half whose branch pixels lie nearer (chessboard
// distance). Returns false, leaving *a and *b alone, for any other cluster.
// `branch` is scratch space, reused from cluster to cluster.
template <typename IsSet>
bool SplitH(const std::vector<cv::Point>& cluster, IsSet is_set, std::vector<cv::Point>* branch_out,
            std::vector<cv::Point>* a, std::vector<cv::Point>* b) {
  // Groups whose centres lie 3 px or more apart in x need a cluster at least
  // that wide: most clusters (one T) are narrower and are not looked into.
  const auto [left, right] =
      std::minmax_element(cluster.begin(), cluster.end(),
                          [](const cv::Point& p, const cv::Point& q) { return p.x < q.x; });
  if (cluster.empty() || right->x - left->x < 3) return false;
  std::vector<cv::Point>& branch = *branch_out;
  branch.clear();
  for (const cv::Point& p : cluster)
    if (CrossingNumber(p, is_set) >= 3) branch.push_back(p);
  if (branch.size() < 2) return false;
  auto touch = [](cv::Point p, cv::Point q) {
    return std::max(std::abs(p.x - q.x), std::abs(p.y - q.y)) <= 1;
  };
  // Groups by flood over the (few) branch pixels.
  std::vector<int> group(branch.size(), -1);
  int groups = 0;
  for (size_t s = 0; s < branch.size(); ++s) {
    if (group[s] >= 0) continue;
    if (groups == 2) return false;
    std::vector<size_t> stack{s};
    group[s] = groups;
    while (!stack.empty()) {
      const size_t i = stack.back();
      stack.pop_back();
      for (size_t j = 0; j < branch.size(); ++j)
        if (group[j] < 0 && touch(branch[i], branch[j])) group[j] = groups, stack.push_back(j);
    }
    ++groups;
  }
  if (groups != 2) return false;
  cv::Point2d centre[2] = {{0, 0}, {0, 0}};
  int count[2] = {0, 0};
  for (size_t i = 0; i < branch.size(); ++i) {
    centre[group[i]] += cv::Point2d(branch[i].x, branch[i].y);
    ++count[group[i]];
  }
  centre[0] *= 1.0 / count[0];
  centre[1] *= 1.0 / count[1];
  const double dx = std::abs(centre[0].x - centre[1].x), dy = std::abs(centre[0].y - centre[1].y);
  if (dx < 3.0 || 2.0 * dy > dx) return false;
  std::vector<cv::Point> halves[2];
  for (const cv::Point& p : cluster) {
    int best[2] = {1 << 20, 1 << 20};
    for (size_t i = 0; i < branch.size(); ++i)
      best[group[i]] = std::min(best[group[i]],
                                std::max(std::abs(p.x - branch[i].x), std::abs(p.y - branch[i].y)));
    halves[best[1] < best[0] ? 1 : 0].push_back(p);
  }
  *a = std::move(halves[0]);
  *b = std::move(halves[1]);
  return true;
}

}  // namespace

bool GraphParams::IsValid(std::string* error) const {
  if (departure_probe < 1 || departure_probe > 50) {
    if (error) *error = "departure_probe must lie in 1..50 pixels";
    return false;
  }
  return true;
}

int SkeletonGraph::Origin(int h) const {
  const SkeletonEdge& e = edges_[EdgeOf(h)];
  return (h & 1) ? e.to : e.from;
}

int SkeletonGraph::Target(int h) const {
  const SkeletonEdge& e = edges_[EdgeOf(h)];
  return (h & 1) ? e.from : e.to;
}

std::vector<cv::Point> SkeletonGraph::Pixels(int h) const {
  const auto& px = edges_[EdgeOf(h)].pixels;
  if (h & 1) return {px.rbegin(), px.rend()};
  return px;
}

int SkeletonGraph::NodeAt(cv::Point p) const {
  if (!Inside(owner_, p.x, p.y)) return kNone;
  const int v = owner_.at<int>(p);
  return v >= 0 ? v : kNone;
}

int SkeletonGraph::EdgeAt(cv::Point p) const {
  if (!Inside(owner_, p.x, p.y)) return kNone;
  const int v = owner_.at<int>(p);
  return v <= -2 ? DecodeEdge(v) : kNone;
}

int SkeletonGraph::NextInFace(int h) const {
  const int twin = Twin(h);
  const int v = Origin(twin);
  const auto& rot = nodes_[v].rotation;
  const int k = rotation_index_[twin];
  const int n = static_cast<int>(rot.size());
  return rot[(k - 1 + n) % n];
}

std::vector<std::vector<int>> SkeletonGraph::Faces() const {
  std::vector<std::vector<int>> faces;
  std::vector<char> seen(HalfEdgeCount(), 0);
  for (int start = 0; start < HalfEdgeCount(); ++start) {
    if (seen[start]) continue;
    std::vector<int> face;
    int h = start;
    while (!seen[h]) {
      seen[h] = 1;
      face.push_back(h);
      h = NextInFace(h);
    }
    faces.push_back(std::move(face));
  }
  return faces;
}

double SkeletonGraph::SignedArea2(const std::vector<int>& face) const {
  // Shoelace over node centres and chain pixels, with y flipped so that
  // anticlockwise on screen is positive; the polygon is walked on the fly.
  bool started = false;
  cv::Point2d first, prev;
  double a = 0.0;
  auto add = [&](const cv::Point2d& q) {
    if (started)
      a += prev.x * (-q.y) - q.x * (-prev.y);
    else
      first = q;
    started = true;
    prev = q;
  };
  for (int h : face) {
    add(nodes_[Origin(h)].centre);
    const std::vector<cv::Point>& px = edges_[EdgeOf(h)].pixels;
    if (h & 1)
      for (auto it = px.rbegin(); it != px.rend(); ++it) add(cv::Point2d(it->x, it->y));
    else
      for (const cv::Point& p : px) add(cv::Point2d(p.x, p.y));
  }
  if (started) add(first);  // closes the polygon (last to first)
  return a;
}

// The steps of one Build, on the skeleton as a 0/1 buffer with a one-pixel
// frame (so that neighbour look-ups need no bounds checks: frame pixels are
// unset, of degree 0), its set pixels, their degrees and the owner of every
// pixel (laid out like the buffer, frame -1). Each step adds to the graph
// `g`, in the order Build calls them.
class SkeletonGraph::Builder {
 public:
  // Fills the 0/1 buffer, lists the set pixels in raster order with the
  // corners of 4-connected steps cleared, counts their degrees and sets
  // every owner to kNone (g's owner image: a view of the buffer's inner part),
  // asking `cancel` between bands of the owners (a fresh 4 bytes a pixel:
  // on 8 Mpx, most of the build's time goes on the memory's first touch).
  Builder(const cv::Mat& skeleton, SkeletonGraph* g, const Cancellation& cancel);

  void FindJunctionClusters();
  void JoinEnclosedPixels();
  void SplitDoubleTs();
  void AddLineEnds();
  void TraceChains();
  void AnchorClosedChains();
  void SetCentres();
  void SetDeparturesAndRotations(const GraphParams& params);

 private:
  // A set pixel with its buffer index.
  struct Lit {
    size_t i;
    cv::Point p;
  };

  size_t At(int x, int y) const {
    return static_cast<size_t>(y + 1) * static_cast<size_t>(stride_) + static_cast<size_t>(x + 1);
  }
  bool Set(int x, int y) const { return bin_[At(x, y)] != 0; }
  // The number of set 8-neighbours of buffer index i.
  int Neighbours(size_t i) const {
    const uchar* up = &bin_[i - static_cast<size_t>(stride_)];
    const uchar* here = &bin_[i];
    const uchar* down = &bin_[i + static_cast<size_t>(stride_)];
    return up[-1] + up[0] + up[1] + here[-1] + here[1] + down[-1] + down[0] + down[1];
  }
  // The chain-code neighbour c of buffer index i.
  size_t Neighbour(size_t i, int c) const {
    return static_cast<size_t>(static_cast<std::ptrdiff_t>(i) + step_[c]);
  }
  // The pixel of buffer index i.
  cv::Point PointOf(size_t i) const {
    return cv::Point(static_cast<int>(i % static_cast<size_t>(stride_)) - 1,
                     static_cast<int>(i / static_cast<size_t>(stride_)) - 1);
  }
  int& Owner(int x, int y) { return owner_data_[At(x, y)]; }
  int& OwnerAt(size_t i) { return owner_data_[i]; }
  int NewNode(NodeKind kind) {
    g_.nodes_.push_back(SkeletonNode{kind, {}, {}, {}});
    return static_cast<int>(g_.nodes_.size()) - 1;
  }

  void ListSetPixels();
  void DropStepCorners();
  void TraceFrom(int node, cv::Point start, cv::Point first);

  SkeletonGraph& g_;
  int rows_;
  int cols_;
  int stride_;
  std::vector<uchar> bin_;
  std::vector<Lit> lit_;
  std::vector<uchar> deg_;
  cv::Mat owners_;
  int* owner_data_ = nullptr;
  std::array<std::ptrdiff_t, 8> step_;          // the chain-code neighbours by buffer index
  std::set<std::pair<int, int>> direct_links_;  // node pairs joined without chain pixels
};

SkeletonGraph::Builder::Builder(const cv::Mat& skeleton, SkeletonGraph* g,
                                const Cancellation& cancel)
    : g_(*g), rows_(skeleton.rows), cols_(skeleton.cols), stride_(skeleton.cols + 2) {
  bin_.assign(static_cast<size_t>(stride_) * static_cast<size_t>(rows_ + 2), 0);
  {
    cv::Mat inner = cv::Mat(rows_ + 2, stride_, CV_8UC1, bin_.data())(cv::Rect(1, 1, cols_, rows_));
    cv::threshold(skeleton, inner, 0, 1, cv::THRESH_BINARY);  // 0 / 1
  }
  ListSetPixels();
  DropStepCorners();
  deg_.assign(bin_.size(), 0);
  for (const Lit& l : lit_) deg_[l.i] = static_cast<uchar>(Neighbours(l.i));

  owners_.create(rows_ + 2, stride_, CV_32S);
  owner_data_ = owners_.ptr<int>(0);  // continuous: freshly allocated
  static_assert(kNone == -1);         // every byte 0xFF
  constexpr int kBandRows = 256;
  for (int y = 0; y < owners_.rows; y += kBandRows) {
    cancel.ThrowIfRequested("the skeleton graph");
    const int band = std::min(kBandRows, owners_.rows - y);
    std::memset(owners_.ptr<int>(y), 0xFF, static_cast<size_t>(band) * stride_ * sizeof(int));
  }
  g_.owner_ = owners_(cv::Rect(1, 1, cols_, rows_));
  for (int c = 0; c < 8; ++c) step_[c] = kCodeDy[c] * std::ptrdiff_t{stride_} + kCodeDx[c];
}

// Lists every set pixel in lit_, in raster order. Only the set pixels are
// visited from here on (a skeleton is sparse), each with its buffer index.
void SkeletonGraph::Builder::ListSetPixels() {
  for (int y = 0; y < rows_; ++y) {
    const uchar* row = &bin_[At(0, y)];
    int x = 0;
    for (; x + 8 <= cols_; x += 8) {         // eight pixels (0 / 1 bytes) at a time
      if (x % 32 == 0 && x + 32 <= cols_) {  // skip empty 32-pixel runs
        std::uint64_t words[4];
        std::memcpy(words, row + x, 32);
        if (!(words[0] | words[1] | words[2] | words[3])) {
          x += 24;  // and 8 by the loop
          continue;
        }
      }
      std::uint64_t word;
      std::memcpy(&word, row + x, 8);
      static_assert(std::endian::native == std::endian::little);
      while (word) {  // pixel x + k is bit 8k
        const int px = x + std::countr_zero(word) / 8;
        lit_.push_back({At(px, y), {px, y}});
        word &= word - 1;
      }
    }
    for (; x < cols_; ++x)
      if (row[x]) lit_.push_back({At(x, y), {x, y}});
  }
}

// Clears the corner pixels of 4-connected steps (an L of three pixels) from
// the buffer and from lit_: they make their neighbours look like
// junctions; the skeleton stays 8-connected without them.
void SkeletonGraph::Builder::DropStepCorners() {
  for (const Lit& l : lit_) {
    const size_t i = l.i;
    if (Neighbours(i) != 2) continue;
    const bool horizontal = bin_[i - 1] || bin_[i + 1];
    const bool vertical =
        bin_[i - static_cast<size_t>(stride_)] || bin_[i + static_cast<size_t>(stride_)];
    if (horizontal && vertical) bin_[i] = 0;
  }
  std::erase_if(lit_, [&](const Lit& l) { return !bin_[l.i]; });
}

// Junction clusters: one junction node per 8-connected group of pixels with
// three or more neighbours, owning them.
void SkeletonGraph::Builder::FindJunctionClusters() {
  std::vector<Lit> stack;
  for (const Lit& l0 : lit_) {
    if (deg_[l0.i] < 3 || OwnerAt(l0.i) != kNone) continue;
    const int id = NewNode(NodeKind::kJunction);
    stack.assign(1, l0);
    OwnerAt(l0.i) = id;
    while (!stack.empty()) {
      const Lit l = stack.back();
      stack.pop_back();
      g_.nodes_[id].pixels.push_back(l.p);
      for (int c = 0; c < 8; ++c) {
        const size_t q = Neighbour(l.i, c);
        if (deg_[q] < 3) continue;  // also in the frame
        if (OwnerAt(q) != kNone) continue;
        OwnerAt(q) = id;
        stack.push_back({q, l.p + CodeStep(c)});
      }
    }
  }
}

// Joins to a cluster every two-neighbour pixel whose neighbours all belong
// to it. Pixels are taken in raster order, each seeing the pixels
// joined before it; only those next to a cluster pixel, or to a pixel
// joined before them, can join, so those alone are visited (a min-heap of
// buffer indices keeps the raster order).
void SkeletonGraph::Builder::JoinEnclosedPixels() {
  std::vector<size_t> heap;
  auto offer = [&](size_t i) {  // a neighbour that might join
    if (deg_[i] == 2 && OwnerAt(i) == kNone) {
      heap.push_back(i);
      std::push_heap(heap.begin(), heap.end(), std::greater<>());
    }
  };
  for (const SkeletonNode& node : g_.nodes_)
    for (const cv::Point& p : node.pixels)
      for (int c = 0; c < 8; ++c) offer(Neighbour(At(p.x, p.y), c));
  size_t last = 0;  // the index taken last (0 lies in the frame)
  while (!heap.empty()) {
    std::pop_heap(heap.begin(), heap.end(), std::greater<>());
    const size_t i = heap.back();
    heap.pop_back();
    if (i == last) continue;  // offered twice
    last = i;
    if (OwnerAt(i) != kNone) continue;
    int cluster = kNone;
    bool same = true;
    for (int c = 0; c < 8 && same; ++c) {
      if (!bin_[Neighbour(i, c)]) continue;
      const int o = OwnerAt(Neighbour(i, c));
      if (o < 0 || g_.nodes_[o].kind != NodeKind::kJunction)
        same = false;
      else if (cluster == kNone)
        cluster = o;
      else if (cluster != o)
        same = false;
    }
    if (!same || cluster == kNone) continue;
    OwnerAt(i) = cluster;
    g_.nodes_[cluster].pixels.push_back(PointOf(i));
    for (int c = 0; c < 8; ++c)
      if (Neighbour(i, c) > i) offer(Neighbour(i, c));  // only pixels after it see it
  }
}

// Thesis 5.1.4.8: where two lines run a few pixels apart, the short segment
// between them puts its two T-junctions into one cluster (an H of four
// branches, which reads as a crossing). Such a cluster holds two groups of
// branch pixels (three or more separate runs of neighbours) side by side;
// it is split between them when each half keeps a line up and down.
// Splits every such cluster into two junction nodes.
void SkeletonGraph::Builder::SplitDoubleTs() {
  const int clusters = static_cast<int>(g_.nodes_.size());
  std::vector<cv::Point> branch;
  for (int id = 0; id < clusters; ++id) {
    const std::vector<cv::Point>& pixels = g_.nodes_[id].pixels;  // until a node is added
    if (pixels.size() < 3) continue;
    std::vector<cv::Point> halves[2];
    if (!SplitH(
            pixels, [&](int x, int y) { return Set(x, y); }, &branch, &halves[0], &halves[1]))
      continue;
    // Each half must leave the cluster on exactly two pixels: its line.
    auto exits = [&](const std::vector<cv::Point>& half) {
      std::set<std::pair<int, int>> out;
      for (const cv::Point& p : half)
        for (int c = 0; c < 8; ++c) {
          const int nx = p.x + kCodeDx[c], ny = p.y + kCodeDy[c];
          if (Set(nx, ny) && Owner(nx, ny) != id) out.insert({nx, ny});
        }
      return out.size();
    };
    if (exits(halves[0]) != 2 || exits(halves[1]) != 2) continue;
    const int other = NewNode(NodeKind::kJunction);
    for (const cv::Point& p : halves[1]) Owner(p.x, p.y) = other;
    g_.nodes_[id].pixels = std::move(halves[0]);
    g_.nodes_[other].pixels = std::move(halves[1]);
  }
}

// Line ends: an end node on every one-neighbour pixel no node owns.
void SkeletonGraph::Builder::AddLineEnds() {
  for (const Lit& l : lit_)
    if (deg_[l.i] == 1 && OwnerAt(l.i) == kNone) {
      const int id = NewNode(NodeKind::kEnd);
      g_.nodes_[id].pixels.push_back(l.p);
      OwnerAt(l.i) = id;
    }
}

// Adds the edge from `node` along the chain that leaves its pixel `start`
// through `first`, owning the chain's pixels, to the node it reaches (or to
// a new end node where it stops). Pixels are carried as
// (buffer index, point); a step moves both.
void SkeletonGraph::Builder::TraceFrom(int node, cv::Point start, cv::Point first) {
  SkeletonEdge edge;
  edge.from = node;
  const int id = static_cast<int>(g_.edges_.size());
  const size_t start_i = At(start.x, start.y);
  size_t prev = start_i, cur = At(first.x, first.y);
  cv::Point cur_p = first;
  while (true) {
    const int o = OwnerAt(cur);
    if (o >= 0) {
      edge.to = o;
      break;
    }
    OwnerAt(cur) = EncodeEdge(id);
    edge.pixels.push_back(cur_p);
    int next_c = -1;
    // Prefer stepping onto a node pixel (other than the one we came from at
    // the very start) so chains stop at their junction.
    for (int c = 0; c < 8; ++c) {
      const size_t q = Neighbour(cur, c);
      if (!bin_[q] || q == prev) continue;
      const int o2 = OwnerAt(q);
      if (o2 >= 0) {
        if (edge.pixels.size() == 1 && o2 == node && q != start_i) continue;
        next_c = c;
        break;
      }
      if (o2 == kNone) next_c = c;
    }
    if (next_c < 0) {
      // Dead end inside a chain (cannot happen on a thin skeleton): close at an end node.
      const int end = NewNode(NodeKind::kEnd);
      edge.pixels.pop_back();
      g_.nodes_[end].pixels.push_back(cur_p);
      OwnerAt(cur) = end;
      edge.to = end;
      break;
    }
    prev = cur;
    cur = Neighbour(cur, next_c);
    cur_p += cv::Point(kCodeDx[next_c], kCodeDy[next_c]);
  }
  g_.edges_.push_back(std::move(edge));
}

// Chains between nodes: an edge along each, and one without pixels for
// each pair of nodes that touch.
void SkeletonGraph::Builder::TraceChains() {
  for (int n = 0; n < static_cast<int>(g_.nodes_.size()); ++n) {
    // By index: tracing may add nodes (moving nodes_), never pixels of node n.
    for (size_t k = 0; k < g_.nodes_[n].pixels.size(); ++k) {
      const cv::Point p = g_.nodes_[n].pixels[k];
      const size_t i = At(p.x, p.y);
      for (int c = 0; c < 8; ++c) {
        const size_t q = Neighbour(i, c);
        if (!bin_[q]) continue;
        const int o = OwnerAt(q);
        if (o == kNone) {
          TraceFrom(n, p, p + CodeStep(c));
        } else if (o >= 0 && o != n) {
          const auto key = std::minmax(n, o);
          if (direct_links_.insert(key).second) {
            SkeletonEdge e;
            e.from = n;
            e.to = o;
            g_.edges_.push_back(std::move(e));
          }
        }
      }
    }
  }
}

// Closed chains without any node get an anchor node, and their edge.
void SkeletonGraph::Builder::AnchorClosedChains() {
  for (const Lit& l : lit_) {
    if (OwnerAt(l.i) != kNone || deg_[l.i] == 0) continue;
    const int id = NewNode(NodeKind::kAnchor);
    g_.nodes_[id].pixels.push_back(l.p);
    OwnerAt(l.i) = id;
    for (int c = 0; c < 8; ++c) {
      const size_t q = Neighbour(l.i, c);
      if (bin_[q] && OwnerAt(q) == kNone) {
        TraceFrom(id, l.p, l.p + CodeStep(c));
        break;
      }
    }
  }
}

// Sets every node's centre: the mean of its pixels.
void SkeletonGraph::Builder::SetCentres() {
  for (SkeletonNode& node : g_.nodes_) {
    cv::Point2d sum(0, 0);
    for (const cv::Point& p : node.pixels) sum += cv::Point2d(p.x, p.y);
    node.centre = sum * (1.0 / static_cast<double>(node.pixels.size()));
  }
}

// Departure directions and rotations: sets every half-edge's direction and
// each node's rotation (its outgoing half-edges anticlockwise), with each
// half-edge's place in it.
void SkeletonGraph::Builder::SetDeparturesAndRotations(const GraphParams& params) {
  SkeletonGraph& g = g_;
  const int half_edges = g.HalfEdgeCount();
  g.departure_.assign(half_edges, {0, 0});
  std::vector<double> angle(half_edges, 0.0);
  for (int h = 0; h < half_edges; ++h) {
    const SkeletonEdge& e = g.edges_[EdgeOf(h)];
    const int origin = g.Origin(h);
    const cv::Point2d from = g.nodes_[origin].centre;
    cv::Point2d probe;
    const int len = static_cast<int>(e.pixels.size());
    if (len == 0) {
      probe = g.nodes_[g.Target(h)].centre;
    } else {
      const int k = std::min(params.departure_probe, len) - 1;
      const cv::Point p = (h & 1) ? e.pixels[len - 1 - k] : e.pixels[k];
      probe = cv::Point2d(p.x, p.y);
      if (len < params.departure_probe) probe = g.nodes_[g.Target(h)].centre;
    }
    cv::Point2d d = probe - from;
    if (std::hypot(d.x, d.y) < 1e-9) {
      // Degenerate (a loop hugging its node): fall back to the first chain pixel.
      const cv::Point p = (h & 1) ? e.pixels.back() : e.pixels.front();
      d = cv::Point2d(p.x, p.y) - from;
    }
    const double n = std::hypot(d.x, d.y);
    g.departure_[h] = n > 0 ? d * (1.0 / n) : cv::Point2d(1, 0);
    angle[h] = std::atan2(-g.departure_[h].y, g.departure_[h].x);
    g.nodes_[origin].rotation.push_back(h);
  }
  g.rotation_index_.assign(half_edges, 0);
  for (SkeletonNode& node : g.nodes_) {
    std::sort(node.rotation.begin(), node.rotation.end(),
              [&](int a, int b) { return angle[a] < angle[b]; });
    for (int i = 0; i < static_cast<int>(node.rotation.size()); ++i)
      g.rotation_index_[node.rotation[i]] = i;
  }
}

SkeletonGraph SkeletonGraph::Build(const cv::Mat& skeleton, const GraphParams& params,
                                   const Cancellation& cancel) {
  if (skeleton.empty()) throw std::invalid_argument("SkeletonGraph::Build: empty skeleton");
  if (skeleton.type() != CV_8UC1)
    throw std::invalid_argument("SkeletonGraph::Build: skeleton must be CV_8UC1");
  std::string why;
  if (!params.IsValid(&why)) throw std::invalid_argument("SkeletonGraph::Build: " + why);

  SkeletonGraph g;
  g.size_ = skeleton.size();
  Builder builder(skeleton, &g, cancel);
  // Nodes: junction clusters (with the pixels they enclose, double Ts
  // split), then line ends; then the chains between them as edges, closed
  // chains anchored; then the directions in which edges leave their nodes.
  constexpr std::string_view kStage = "the skeleton graph";
  builder.FindJunctionClusters();
  cancel.ThrowIfRequested(kStage);
  builder.JoinEnclosedPixels();
  builder.SplitDoubleTs();
  builder.AddLineEnds();
  cancel.ThrowIfRequested(kStage);
  builder.TraceChains();
  cancel.ThrowIfRequested(kStage);
  builder.AnchorClosedChains();
  builder.SetCentres();
  builder.SetDeparturesAndRotations(params);
  return g;
}

}  // namespace bsls::interpretation
