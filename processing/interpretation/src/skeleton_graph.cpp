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

SkeletonGraph SkeletonGraph::Build(const cv::Mat& skeleton, const GraphParams& params) {
  if (skeleton.empty()) throw std::invalid_argument("SkeletonGraph::Build: empty skeleton");
  if (skeleton.type() != CV_8UC1)
    throw std::invalid_argument("SkeletonGraph::Build: skeleton must be CV_8UC1");
  std::string why;
  if (!params.IsValid(&why)) throw std::invalid_argument("SkeletonGraph::Build: " + why);

  SkeletonGraph g;
  g.size_ = skeleton.size();
  const int rows = skeleton.rows, cols = skeleton.cols;

  // Binary image (0 / 1) and degrees with a one-pixel frame, so that
  // neighbour look-ups need no bounds checks: frame pixels are unset, of
  // degree 0.
  const int stride = cols + 2;
  std::vector<uchar> bin(static_cast<size_t>(stride) * static_cast<size_t>(rows + 2), 0);
  {
    cv::Mat inner = cv::Mat(rows + 2, stride, CV_8UC1, bin.data())(cv::Rect(1, 1, cols, rows));
    cv::threshold(skeleton, inner, 0, 1, cv::THRESH_BINARY);  // 0 / 1
  }
  auto at = [stride](int x, int y) {
    return static_cast<size_t>(y + 1) * static_cast<size_t>(stride) + static_cast<size_t>(x + 1);
  };
  auto set = [&](int x, int y) { return bin[at(x, y)] != 0; };
  auto neighbours = [&](size_t i) {  // the number of set 8-neighbours
    const uchar* up = &bin[i - static_cast<size_t>(stride)];
    const uchar* here = &bin[i];
    const uchar* down = &bin[i + static_cast<size_t>(stride)];
    return up[-1] + up[0] + up[1] + here[-1] + here[1] + down[-1] + down[0] + down[1];
  };
  // Only the set pixels are visited from here on (a skeleton is sparse),
  // each with its buffer index.
  struct Lit {
    size_t i;
    cv::Point p;
  };
  std::vector<Lit> lit;
  for (int y = 0; y < rows; ++y) {
    const uchar* row = &bin[at(0, y)];
    int x = 0;
    for (; x + 8 <= cols; x += 8) {         // eight pixels (0 / 1 bytes) at a time
      if (x % 32 == 0 && x + 32 <= cols) {  // skip empty 32-pixel runs
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
        lit.push_back({at(px, y), {px, y}});
        word &= word - 1;
      }
    }
    for (; x < cols; ++x)
      if (row[x]) lit.push_back({at(x, y), {x, y}});
  }
  // Corner pixels of 4-connected steps (an L of three pixels) make their
  // neighbours look like junctions; the skeleton stays 8-connected without them.
  for (const Lit& l : lit) {
    const size_t i = l.i;
    if (neighbours(i) != 2) continue;
    const bool horizontal = bin[i - 1] || bin[i + 1];
    const bool vertical =
        bin[i - static_cast<size_t>(stride)] || bin[i + static_cast<size_t>(stride)];
    if (horizontal && vertical) bin[i] = 0;
  }
  std::erase_if(lit, [&](const Lit& l) { return !bin[l.i]; });
  std::vector<uchar> deg(bin.size(), 0);
  for (const Lit& l : lit) deg[l.i] = static_cast<uchar>(neighbours(l.i));

  // Owners in a buffer laid out like bin (frame -1); the graph keeps its image part.
  cv::Mat owners(rows + 2, stride, CV_32S);
  int* const owner_data = owners.ptr<int>(0);  // continuous: freshly allocated
  static_assert(kNone == -1);                  // every byte 0xFF
  std::memset(owner_data, 0xFF, owners.total() * sizeof(int));
  g.owner_ = owners(cv::Rect(1, 1, cols, rows));
  auto owner = [&](int x, int y) -> int& { return owner_data[at(x, y)]; };
  auto owner_at = [owner_data](size_t i) -> int& { return owner_data[i]; };
  // The chain-code neighbours by buffer index, and buffer indices back to pixels.
  std::array<std::ptrdiff_t, 8> step;
  for (int c = 0; c < 8; ++c) step[c] = kCodeDy[c] * std::ptrdiff_t{stride} + kCodeDx[c];
  auto neighbour = [&step](size_t i, int c) {
    return static_cast<size_t>(static_cast<std::ptrdiff_t>(i) + step[c]);
  };
  auto point_of = [stride](size_t i) {
    return cv::Point(static_cast<int>(i % static_cast<size_t>(stride)) - 1,
                     static_cast<int>(i / static_cast<size_t>(stride)) - 1);
  };

  // Junction clusters: 8-connected groups of pixels with three or more neighbours.
  auto new_node = [&](NodeKind kind) {
    g.nodes_.push_back(SkeletonNode{kind, {}, {}, {}});
    return static_cast<int>(g.nodes_.size()) - 1;
  };
  std::vector<Lit> stack;
  for (const Lit& l0 : lit) {
    if (deg[l0.i] < 3 || owner_at(l0.i) != kNone) continue;
    const int id = new_node(NodeKind::kJunction);
    stack.assign(1, l0);
    owner_at(l0.i) = id;
    while (!stack.empty()) {
      const Lit l = stack.back();
      stack.pop_back();
      g.nodes_[id].pixels.push_back(l.p);
      for (int c = 0; c < 8; ++c) {
        const size_t q = neighbour(l.i, c);
        if (deg[q] < 3) continue;  // also in the frame
        if (owner_at(q) != kNone) continue;
        owner_at(q) = id;
        stack.push_back({q, l.p + CodeStep(c)});
      }
    }
  }
  // A two-neighbour pixel whose neighbours all belong to one cluster is part
  // of it. Pixels are taken in raster order, each seeing the pixels joined
  // before it; only those next to a cluster pixel, or to a pixel joined
  // before them, can join, so those alone are visited (a min-heap of buffer
  // indices keeps the raster order).
  {
    std::vector<size_t> heap;
    auto offer = [&](size_t i) {  // a neighbour that might join
      if (deg[i] == 2 && owner_at(i) == kNone) {
        heap.push_back(i);
        std::push_heap(heap.begin(), heap.end(), std::greater<>());
      }
    };
    for (const SkeletonNode& node : g.nodes_)
      for (const cv::Point& p : node.pixels)
        for (int c = 0; c < 8; ++c) offer(neighbour(at(p.x, p.y), c));
    size_t last = 0;  // the index taken last (0 lies in the frame)
    while (!heap.empty()) {
      std::pop_heap(heap.begin(), heap.end(), std::greater<>());
      const size_t i = heap.back();
      heap.pop_back();
      if (i == last) continue;  // offered twice
      last = i;
      if (owner_at(i) != kNone) continue;
      int cluster = kNone;
      bool same = true;
      for (int c = 0; c < 8 && same; ++c) {
        if (!bin[neighbour(i, c)]) continue;
        const int o = owner_at(neighbour(i, c));
        if (o < 0 || g.nodes_[o].kind != NodeKind::kJunction)
          same = false;
        else if (cluster == kNone)
          cluster = o;
        else if (cluster != o)
          same = false;
      }
      if (!same || cluster == kNone) continue;
      owner_at(i) = cluster;
      g.nodes_[cluster].pixels.push_back(point_of(i));
      for (int c = 0; c < 8; ++c)
        if (neighbour(i, c) > i) offer(neighbour(i, c));  // only pixels after it see it
    }
  }
  // Thesis 5.1.4.8: where two lines run a few pixels apart, the short segment
  // between them puts its two T-junctions into one cluster (an H of four
  // branches, which reads as a crossing). Such a cluster holds two groups of
  // branch pixels (three or more separate runs of neighbours) side by side;
  // it is split between them when each half keeps a line up and down.
  const int clusters = static_cast<int>(g.nodes_.size());
  std::vector<cv::Point> branch;
  for (int id = 0; id < clusters; ++id) {
    const std::vector<cv::Point>& pixels = g.nodes_[id].pixels;  // until a node is added
    if (pixels.size() < 3) continue;
    std::vector<cv::Point> halves[2];
    if (!SplitH(
            pixels, [&](int x, int y) { return set(x, y); }, &branch, &halves[0], &halves[1]))
      continue;
    // Each half must leave the cluster on exactly two pixels: its line.
    auto exits = [&](const std::vector<cv::Point>& half) {
      std::set<std::pair<int, int>> out;
      for (const cv::Point& p : half)
        for (int c = 0; c < 8; ++c) {
          const int nx = p.x + kCodeDx[c], ny = p.y + kCodeDy[c];
          if (set(nx, ny) && owner(nx, ny) != id) out.insert({nx, ny});
        }
      return out.size();
    };
    if (exits(halves[0]) != 2 || exits(halves[1]) != 2) continue;
    const int other = new_node(NodeKind::kJunction);
    for (const cv::Point& p : halves[1]) owner(p.x, p.y) = other;
    g.nodes_[id].pixels = std::move(halves[0]);
    g.nodes_[other].pixels = std::move(halves[1]);
  }

  // Line ends.
  for (const Lit& l : lit)
    if (deg[l.i] == 1 && owner_at(l.i) == kNone) {
      const int id = new_node(NodeKind::kEnd);
      g.nodes_[id].pixels.push_back(l.p);
      owner_at(l.i) = id;
    }

  // Chains between nodes.
  std::set<std::pair<int, int>> direct_links;
  // Pixels are carried as (buffer index, point); a step moves both.
  auto trace_from = [&](int node, cv::Point start, cv::Point first) {
    SkeletonEdge edge;
    edge.from = node;
    const int id = static_cast<int>(g.edges_.size());
    const size_t start_i = at(start.x, start.y);
    size_t prev = start_i, cur = at(first.x, first.y);
    cv::Point cur_p = first;
    while (true) {
      const int o = owner_at(cur);
      if (o >= 0) {
        edge.to = o;
        break;
      }
      owner_at(cur) = EncodeEdge(id);
      edge.pixels.push_back(cur_p);
      int next_c = -1;
      // Prefer stepping onto a node pixel (other than the one we came from at
      // the very start) so chains stop at their junction.
      for (int c = 0; c < 8; ++c) {
        const size_t q = neighbour(cur, c);
        if (!bin[q] || q == prev) continue;
        const int o2 = owner_at(q);
        if (o2 >= 0) {
          if (edge.pixels.size() == 1 && o2 == node && q != start_i) continue;
          next_c = c;
          break;
        }
        if (o2 == kNone) next_c = c;
      }
      if (next_c < 0) {
        // Dead end inside a chain (cannot happen on a thin skeleton): close at an end node.
        const int end = new_node(NodeKind::kEnd);
        edge.pixels.pop_back();
        g.nodes_[end].pixels.push_back(cur_p);
        owner_at(cur) = end;
        edge.to = end;
        break;
      }
      prev = cur;
      cur = neighbour(cur, next_c);
      cur_p += cv::Point(kCodeDx[next_c], kCodeDy[next_c]);
    }
    g.edges_.push_back(std::move(edge));
  };
  for (int n = 0; n < static_cast<int>(g.nodes_.size()); ++n) {
    // By index: tracing may add nodes (moving nodes_), never pixels of node n.
    for (size_t k = 0; k < g.nodes_[n].pixels.size(); ++k) {
      const cv::Point p = g.nodes_[n].pixels[k];
      const size_t i = at(p.x, p.y);
      for (int c = 0; c < 8; ++c) {
        const size_t q = neighbour(i, c);
        if (!bin[q]) continue;
        const int o = owner_at(q);
        if (o == kNone) {
          trace_from(n, p, p + CodeStep(c));
        } else if (o >= 0 && o != n) {
          const auto key = std::minmax(n, o);
          if (direct_links.insert(key).second) {
            SkeletonEdge e;
            e.from = n;
            e.to = o;
            g.edges_.push_back(std::move(e));
          }
        }
      }
    }
  }
  // Closed chains without any node get an anchor.
  for (const Lit& l : lit) {
    if (owner_at(l.i) != kNone || deg[l.i] == 0) continue;
    const int id = new_node(NodeKind::kAnchor);
    g.nodes_[id].pixels.push_back(l.p);
    owner_at(l.i) = id;
    for (int c = 0; c < 8; ++c) {
      const size_t q = neighbour(l.i, c);
      if (bin[q] && owner_at(q) == kNone) {
        trace_from(id, l.p, l.p + CodeStep(c));
        break;
      }
    }
  }

  for (SkeletonNode& node : g.nodes_) {
    cv::Point2d sum(0, 0);
    for (const cv::Point& p : node.pixels) sum += cv::Point2d(p.x, p.y);
    node.centre = sum * (1.0 / static_cast<double>(node.pixels.size()));
  }

  // Departure directions and rotations.
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
  return g;
}

}  // namespace bsls::interpretation
