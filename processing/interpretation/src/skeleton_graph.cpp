#include "bsls/interpretation/skeleton_graph.h"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <set>
#include <stdexcept>

#include "bsls/interpretation/chain_code.h"

namespace bsls::interpretation {
namespace {

constexpr int kNone = -1;

bool Inside(const cv::Mat& m, int x, int y) { return x >= 0 && y >= 0 && x < m.cols && y < m.rows; }

int EncodeEdge(int e) { return -e - 2; }
int DecodeEdge(int v) { return -v - 2; }

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
  // anticlockwise on screen is positive.
  std::vector<cv::Point2d> poly;
  for (int h : face) {
    poly.push_back(nodes_[Origin(h)].centre);
    for (const cv::Point& p : Pixels(h)) poly.emplace_back(p.x, p.y);
  }
  double a = 0.0;
  for (size_t i = 0; i < poly.size(); ++i) {
    const cv::Point2d& p = poly[i];
    const cv::Point2d& q = poly[(i + 1) % poly.size()];
    a += p.x * (-q.y) - q.x * (-p.y);
  }
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

  // Binary image with a one-pixel frame so neighbour look-ups need no bounds checks.
  cv::Mat bin = cv::Mat::zeros(rows + 2, cols + 2, CV_8UC1);
  {
    cv::Mat inner = bin(cv::Rect(1, 1, cols, rows));
    cv::compare(skeleton, 0, inner, cv::CMP_NE);
    inner /= 255;
  }
  auto set = [&](int x, int y) { return bin.at<uchar>(y + 1, x + 1) != 0; };
  // Corner pixels of 4-connected steps (an L of three pixels) make their
  // neighbours look like junctions; the skeleton stays 8-connected without them.
  // Only the set pixels are visited from here on (a skeleton is sparse).
  std::vector<cv::Point> lit;
  cv::findNonZero(skeleton, lit);
  for (const cv::Point& p : lit) {
    const int x = p.x, y = p.y;
    int n = 0;
    for (int c = 0; c < 8; ++c) n += set(x + kCodeDx[c], y + kCodeDy[c]);
    if (n != 2) continue;
    const bool horizontal = set(x - 1, y) || set(x + 1, y);
    const bool vertical = set(x, y - 1) || set(x, y + 1);
    if (horizontal && vertical) bin.at<uchar>(y + 1, x + 1) = 0;
  }
  std::erase_if(lit, [&](const cv::Point& p) { return !set(p.x, p.y); });
  auto degree = [&](int x, int y) {
    int d = 0;
    for (int c = 0; c < 8; ++c) d += set(x + kCodeDx[c], y + kCodeDy[c]);
    return d;
  };

  g.owner_ = cv::Mat(rows, cols, CV_32S, cv::Scalar(kNone));
  cv::Mat deg(rows, cols, CV_8UC1, cv::Scalar(0));
  for (const cv::Point& p : lit) deg.at<uchar>(p) = static_cast<uchar>(degree(p.x, p.y));

  // Junction clusters: 8-connected groups of pixels with three or more neighbours.
  auto new_node = [&](NodeKind kind) {
    g.nodes_.push_back(SkeletonNode{kind, {}, {}, {}});
    return static_cast<int>(g.nodes_.size()) - 1;
  };
  for (const cv::Point& p0 : lit) {
    {
      const int x = p0.x, y = p0.y;
      if (deg.at<uchar>(y, x) < 3 || g.owner_.at<int>(y, x) != kNone) continue;
      const int id = new_node(NodeKind::kJunction);
      std::vector<cv::Point> stack{{x, y}};
      g.owner_.at<int>(y, x) = id;
      while (!stack.empty()) {
        const cv::Point p = stack.back();
        stack.pop_back();
        g.nodes_[id].pixels.push_back(p);
        for (int c = 0; c < 8; ++c) {
          const int nx = p.x + kCodeDx[c], ny = p.y + kCodeDy[c];
          if (!Inside(deg, nx, ny) || deg.at<uchar>(ny, nx) < 3) continue;
          if (g.owner_.at<int>(ny, nx) != kNone) continue;
          g.owner_.at<int>(ny, nx) = id;
          stack.push_back({nx, ny});
        }
      }
    }
  }
  // A two-neighbour pixel whose neighbours all belong to one cluster is part of it.
  for (const cv::Point& p0 : lit) {
    {
      const int x = p0.x, y = p0.y;
      if (deg.at<uchar>(y, x) != 2 || g.owner_.at<int>(y, x) != kNone) continue;
      int cluster = kNone;
      bool same = true;
      for (int c = 0; c < 8 && same; ++c) {
        const int nx = x + kCodeDx[c], ny = y + kCodeDy[c];
        if (!Inside(deg, nx, ny) || !set(nx, ny)) continue;
        const int o = g.owner_.at<int>(ny, nx);
        if (o < 0 || g.nodes_[o].kind != NodeKind::kJunction) same = false;
        else if (cluster == kNone) cluster = o;
        else if (cluster != o) same = false;
      }
      if (same && cluster != kNone) {
        g.owner_.at<int>(y, x) = cluster;
        g.nodes_[cluster].pixels.push_back({x, y});
      }
    }
  }
  // Line ends.
  for (const cv::Point& p : lit)
    if (deg.at<uchar>(p) == 1 && g.owner_.at<int>(p) == kNone) {
      const int id = new_node(NodeKind::kEnd);
      g.nodes_[id].pixels.push_back(p);
      g.owner_.at<int>(p) = id;
    }

  // Chains between nodes.
  std::set<std::pair<int, int>> direct_links;
  auto trace_from = [&](int node, cv::Point start, cv::Point first) {
    SkeletonEdge edge;
    edge.from = node;
    const int id = static_cast<int>(g.edges_.size());
    cv::Point prev = start, cur = first;
    while (true) {
      const int o = g.owner_.at<int>(cur);
      if (o >= 0) {
        edge.to = o;
        break;
      }
      g.owner_.at<int>(cur) = EncodeEdge(id);
      edge.pixels.push_back(cur);
      cv::Point next(-1, -1);
      // Prefer stepping onto a node pixel (other than the one we came from at
      // the very start) so chains stop at their junction.
      for (int c = 0; c < 8; ++c) {
        const int nx = cur.x + kCodeDx[c], ny = cur.y + kCodeDy[c];
        if (!Inside(deg, nx, ny) || !set(nx, ny) || cv::Point(nx, ny) == prev) continue;
        const int owner = g.owner_.at<int>(ny, nx);
        if (owner >= 0) {
          if (edge.pixels.size() == 1 && owner == node && cv::Point(nx, ny) != start) continue;
          next = {nx, ny};
          break;
        }
        if (owner == kNone) next = {nx, ny};
      }
      if (next.x < 0) {
        // Dead end inside a chain (cannot happen on a thin skeleton): close at an end node.
        const int end = new_node(NodeKind::kEnd);
        edge.pixels.pop_back();
        g.nodes_[end].pixels.push_back(cur);
        g.owner_.at<int>(cur) = end;
        edge.to = end;
        break;
      }
      prev = cur;
      cur = next;
    }
    g.edges_.push_back(std::move(edge));
  };
  for (int n = 0; n < static_cast<int>(g.nodes_.size()); ++n) {
    const std::vector<cv::Point> pixels = g.nodes_[n].pixels;
    for (const cv::Point& p : pixels) {
      for (int c = 0; c < 8; ++c) {
        const int nx = p.x + kCodeDx[c], ny = p.y + kCodeDy[c];
        if (!Inside(deg, nx, ny) || !set(nx, ny)) continue;
        const int o = g.owner_.at<int>(ny, nx);
        if (o == kNone) {
          trace_from(n, p, {nx, ny});
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
  for (const cv::Point& p0 : lit) {
    {
      const int x = p0.x, y = p0.y;
      if (g.owner_.at<int>(y, x) != kNone || deg.at<uchar>(y, x) == 0) continue;
      const int id = new_node(NodeKind::kAnchor);
      g.nodes_[id].pixels.push_back({x, y});
      g.owner_.at<int>(y, x) = id;
      for (int c = 0; c < 8; ++c) {
        const int nx = x + kCodeDx[c], ny = y + kCodeDy[c];
        if (Inside(deg, nx, ny) && set(nx, ny) && g.owner_.at<int>(ny, nx) == kNone) {
          trace_from(id, {x, y}, {nx, ny});
          break;
        }
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
