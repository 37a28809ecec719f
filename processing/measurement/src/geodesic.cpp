#include "bsls/measurement/geodesic.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <queue>
#include <unordered_map>
#include <utility>

namespace bsls::measurement {
namespace {

constexpr int kMaxSteinerPoints = 64;

// The Steiner graph of one mesh with k points per edge; nodes are vertices
// [0, V), Steiner points V + e k + j, then the start S and the end T.
class SteinerGraph {
 public:
  SteinerGraph(const geometry::SurfaceMesh& mesh, int k) : mesh_(mesh), k_(k) {
    const int v_count = static_cast<int>(mesh.positions.size());
    vertex_faces_.resize(v_count);
    std::unordered_map<std::uint64_t, int> edge_ids;
    face_edges_.resize(mesh.faces.size());
    for (std::size_t f = 0; f < mesh.faces.size(); ++f) {
      const Eigen::Vector3i& face = mesh.faces[f];
      for (int j = 0; j < 3; ++j) {
        vertex_faces_[face[j]].push_back(static_cast<int>(f));
        const int a = std::min(face[j], face[(j + 1) % 3]);
        const int b = std::max(face[j], face[(j + 1) % 3]);
        const std::uint64_t key = (static_cast<std::uint64_t>(a) << 32) | static_cast<unsigned>(b);
        auto [it, fresh] = edge_ids.try_emplace(key, static_cast<int>(edges_.size()));
        if (fresh) {
          edges_.emplace_back(a, b);
          edge_faces_.emplace_back();
        }
        edge_faces_[it->second].push_back(static_cast<int>(f));
        face_edges_[f][j] = it->second;
      }
    }
    steiner_begin_ = v_count;
    start_ = steiner_begin_ + static_cast<int>(edges_.size()) * k_;
    end_ = start_ + 1;
  }

  int start() const { return start_; }
  int end() const { return end_; }
  int size() const { return end_ + 1; }

  // Shortest path length from `a` (on face fa) to `b` (on face fb), and the path.
  double Solve(const Eigen::Vector3d& a, int fa, const Eigen::Vector3d& b, int fb,
               std::vector<Eigen::Vector3d>* path) {
    a_ = a;
    b_ = b;
    fa_ = fa;
    fb_ = fb;
    const double infinity = std::numeric_limits<double>::infinity();
    std::vector<double> dist(size(), infinity);
    std::vector<int> previous(size(), -1);
    std::vector<char> done(size(), 0);
    using Entry = std::pair<double, int>;
    std::priority_queue<Entry, std::vector<Entry>, std::greater<>> open;
    dist[start_] = 0.0;
    open.emplace((a - b).norm(), start_);
    std::vector<int> neighbours;
    while (!open.empty()) {
      const int node = open.top().second;
      open.pop();
      if (done[node]) continue;
      done[node] = 1;
      if (node == end_) break;
      const Eigen::Vector3d p = Position(node);
      neighbours.clear();
      for (int f : FacesOf(node)) NodesOf(f, &neighbours);
      for (int n : neighbours) {
        if (n == node || done[n]) continue;
        const Eigen::Vector3d q = Position(n);
        const double candidate = dist[node] + (q - p).norm();
        if (candidate < dist[n]) {
          dist[n] = candidate;
          previous[n] = node;
          open.emplace(candidate + (q - b).norm(), n);
        }
      }
    }
    if (!std::isfinite(dist[end_])) return infinity;
    if (path) {
      path->clear();
      for (int n = end_; n >= 0; n = previous[n]) path->push_back(Position(n));
      std::reverse(path->begin(), path->end());
    }
    return dist[end_];
  }

 private:
  Eigen::Vector3d Position(int node) const {
    if (node == start_) return a_;
    if (node == end_) return b_;
    if (node < steiner_begin_) return mesh_.positions[node];
    const int e = (node - steiner_begin_) / k_;
    const int j = (node - steiner_begin_) % k_;
    const double t = (j + 1.0) / (k_ + 1.0);
    return (1.0 - t) * mesh_.positions[edges_[e].first] + t * mesh_.positions[edges_[e].second];
  }

  std::vector<int> FacesOf(int node) const {
    if (node == start_) return {fa_};
    if (node == end_) return {fb_};
    if (node < steiner_begin_) return vertex_faces_[node];
    return edge_faces_[(node - steiner_begin_) / k_];
  }

  void NodesOf(int f, std::vector<int>* nodes) const {
    for (int j = 0; j < 3; ++j) {
      nodes->push_back(mesh_.faces[f][j]);
      const int first = steiner_begin_ + face_edges_[f][j] * k_;
      for (int s = 0; s < k_; ++s) nodes->push_back(first + s);
    }
    if (f == fa_) nodes->push_back(start_);
    if (f == fb_) nodes->push_back(end_);
  }

  const geometry::SurfaceMesh& mesh_;
  int k_ = 0;
  std::vector<std::vector<int>> vertex_faces_;
  std::vector<std::pair<int, int>> edges_;
  std::vector<std::vector<int>> edge_faces_;
  std::vector<std::array<int, 3>> face_edges_;
  int steiner_begin_ = 0, start_ = 0, end_ = 0;
  Eigen::Vector3d a_, b_;
  int fa_ = -1, fb_ = -1;
};

}  // namespace

bool GeodesicParams::IsValid(std::string* error) const {
  if (steiner_points_per_edge < 0 || steiner_points_per_edge > kMaxSteinerPoints) {
    if (error)
      *error = "geodesic steiner_points_per_edge must lie in [0, " +
               std::to_string(kMaxSteinerPoints) + "]";
    return false;
  }
  return true;
}

GeodesicResult GeodesicDistance(const SurfaceQuery& surface, const Eigen::Vector2d& a_xy,
                                const Eigen::Vector2d& b_xy, const GeodesicParams& params) {
  std::string why;
  if (!params.IsValid(&why)) throw MeasurementError(why);
  const SurfacePoint a = surface.At(a_xy, "geodesic start");
  const SurfacePoint b = surface.At(b_xy, "geodesic end");
  GeodesicResult result;
  result.straight_mm.value = (b.position - a.position).norm();
  result.straight_mm.uncertainty = std::hypot(a.sigma_mm, b.sigma_mm);
  const int k = params.steiner_points_per_edge;
  SteinerGraph graph(surface.mesh(), k);
  const double d = graph.Solve(a.position, a.face, b.position, b.face, &result.path);
  if (!std::isfinite(d))
    throw MeasurementError("geodesic: the surface does not connect the start and end points");
  result.distance_mm.value = d;
  if (params.estimate_discretisation && k > 0) {
    SteinerGraph coarse(surface.mesh(), (k + 1) / 2);
    result.discretisation_mm =
        std::abs(coarse.Solve(a.position, a.face, b.position, b.face, nullptr) - d);
  }
  result.distance_mm.uncertainty = std::sqrt(a.sigma_mm * a.sigma_mm + b.sigma_mm * b.sigma_mm +
                                             result.discretisation_mm * result.discretisation_mm);
  return result;
}

}  // namespace bsls::measurement
