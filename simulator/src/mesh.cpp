#include "bsls/simulator/mesh.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numbers>
#include <unordered_map>

namespace bsls::simulator {
namespace {

// Leaves hold at most this many triangles.
constexpr int kMaxLeafTriangles = 4;
// Traversal stack size; a median-split tree over 2^31 triangles is shallower.
constexpr int kMaxBvhDepth = 60;
// Barycentric slack so rays through shared edges do not slip between triangles.
constexpr double kEdgeSlack = 1e-12;

std::uint64_t EdgeKey(int a, int b) {
  const auto lo = static_cast<std::uint64_t>(std::min(a, b));
  const auto hi = static_cast<std::uint64_t>(std::max(a, b));
  return (hi << 32) | lo;
}

}  // namespace

bool IndexedMesh::IsValid(std::string* error) const {
  auto fail = [error](const std::string& why) {
    if (error) *error = why;
    return false;
  };
  if (triangles.empty()) return fail("mesh has no triangles");
  for (size_t i = 0; i < vertices.size(); ++i)
    if (!vertices[i].allFinite()) return fail("vertex " + std::to_string(i) + " is not finite");
  const int n = static_cast<int>(vertices.size());
  for (size_t i = 0; i < triangles.size(); ++i) {
    const auto& t = triangles[i];
    for (const int index : t)
      if (index < 0 || index >= n)
        return fail("triangle " + std::to_string(i) + " refers to vertex " + std::to_string(index) +
                    " of " + std::to_string(n));
    if (t[0] == t[1] || t[1] == t[2] || t[0] == t[2])
      return fail("triangle " + std::to_string(i) + " repeats a vertex");
  }
  return true;
}

Eigen::AlignedBox3d IndexedMesh::Bounds() const {
  Eigen::AlignedBox3d box;
  for (const auto& v : vertices) box.extend(v);
  return box;
}

IndexedMesh LoopSubdivide(const IndexedMesh& mesh, int levels) {
  IndexedMesh current = mesh;
  for (int level = 0; level < levels; ++level) {
    const int nv = static_cast<int>(current.vertices.size());
    // Edges: endpoints, opposite vertices, number of incident triangles.
    struct Edge {
      int a, b;
      int opposite[2] = {-1, -1};
      int faces = 0;
    };
    std::vector<Edge> edges;
    std::unordered_map<std::uint64_t, int> edge_index;
    edge_index.reserve(current.triangles.size() * 2);
    std::vector<std::array<int, 3>> tri_edges(current.triangles.size());
    for (size_t f = 0; f < current.triangles.size(); ++f) {
      const auto& t = current.triangles[f];
      for (int k = 0; k < 3; ++k) {
        const int a = t[k], b = t[(k + 1) % 3], c = t[(k + 2) % 3];
        auto [it, inserted] = edge_index.try_emplace(EdgeKey(a, b), static_cast<int>(edges.size()));
        if (inserted) edges.push_back({a, b});
        Edge& e = edges[it->second];
        if (e.faces < 2) e.opposite[e.faces] = c;
        ++e.faces;
        tri_edges[f][k] = it->second;
      }
    }
    // Per vertex: neighbours, boundary neighbours, whether it touches a crease.
    std::vector<std::vector<int>> neighbours(nv);
    std::vector<std::vector<int>> boundary_neighbours(nv);
    std::vector<bool> on_crease(nv, false);
    for (const Edge& e : edges) {
      neighbours[e.a].push_back(e.b);
      neighbours[e.b].push_back(e.a);
      if (e.faces == 1) {
        boundary_neighbours[e.a].push_back(e.b);
        boundary_neighbours[e.b].push_back(e.a);
      } else if (e.faces > 2) {
        on_crease[e.a] = on_crease[e.b] = true;
      }
    }
    IndexedMesh next;
    next.vertices.resize(nv + edges.size());
    // Updated old vertices.
    for (int i = 0; i < nv; ++i) {
      const Eigen::Vector3d& v = current.vertices[i];
      const auto& nb = neighbours[i];
      const auto& bnb = boundary_neighbours[i];
      if (on_crease[i] || nb.empty() || (!bnb.empty() && bnb.size() != 2)) {
        next.vertices[i] = v;
      } else if (bnb.size() == 2) {
        next.vertices[i] = 0.75 * v + 0.125 * (current.vertices[bnb[0]] + current.vertices[bnb[1]]);
      } else {
        const double n = static_cast<double>(nb.size());
        const double c = 0.375 + 0.25 * std::cos(2.0 * std::numbers::pi / n);
        const double beta = (0.625 - c * c) / n;
        Eigen::Vector3d sum = Eigen::Vector3d::Zero();
        for (const int j : nb) sum += current.vertices[j];
        next.vertices[i] = (1.0 - n * beta) * v + beta * sum;
      }
    }
    // New edge vertices.
    for (size_t k = 0; k < edges.size(); ++k) {
      const Edge& e = edges[k];
      const Eigen::Vector3d& a = current.vertices[e.a];
      const Eigen::Vector3d& b = current.vertices[e.b];
      if (e.faces == 2) {
        next.vertices[nv + k] = 0.375 * (a + b) + 0.125 * (current.vertices[e.opposite[0]] +
                                                           current.vertices[e.opposite[1]]);
      } else {
        next.vertices[nv + k] = 0.5 * (a + b);
      }
    }
    next.triangles.reserve(current.triangles.size() * 4);
    for (size_t f = 0; f < current.triangles.size(); ++f) {
      const auto& t = current.triangles[f];
      // Edge k joins t[k] and t[k+1].
      const int e01 = nv + tri_edges[f][0];
      const int e12 = nv + tri_edges[f][1];
      const int e20 = nv + tri_edges[f][2];
      next.triangles.push_back({t[0], e01, e20});
      next.triangles.push_back({t[1], e12, e01});
      next.triangles.push_back({t[2], e20, e12});
      next.triangles.push_back({e01, e12, e20});
    }
    current = std::move(next);
  }
  return current;
}

std::vector<Eigen::Vector3d> VertexNormals(const IndexedMesh& mesh) {
  std::vector<Eigen::Vector3d> normals(mesh.vertices.size(), Eigen::Vector3d::Zero());
  for (const auto& t : mesh.triangles) {
    // The cross product's length is twice the area: area weighting for free.
    const Eigen::Vector3d n = (mesh.vertices[t[1]] - mesh.vertices[t[0]])
                                  .cross(mesh.vertices[t[2]] - mesh.vertices[t[0]]);
    for (const int i : t) normals[i] += n;
  }
  for (auto& n : normals) {
    const double length = n.norm();
    if (length > 0.0) n /= length;
  }
  return normals;
}

IndexedMesh Transformed(const IndexedMesh& mesh, const Eigen::Affine3d& transform) {
  IndexedMesh out = mesh;
  for (auto& v : out.vertices) v = transform * v;
  return out;
}

MeshSurface::MeshSurface(IndexedMesh mesh, std::string name)
    : mesh_(std::move(mesh)), name_(std::move(name)) {
  std::string error;
  if (!mesh_.IsValid(&error)) throw std::invalid_argument("MeshSurface '" + name_ + "': " + error);
  vertex_normals_ = VertexNormals(mesh_);
  const int count = static_cast<int>(mesh_.triangles.size());
  std::vector<int> order(count);
  for (int i = 0; i < count; ++i) order[i] = i;
  nodes_.reserve(2 * count / kMaxLeafTriangles + 2);
  Build(order, 0, count, 0);
  triangles_.reserve(count);
  for (const int index : order) {
    const auto& t = mesh_.triangles[index];
    Triangle tri;
    tri.v0 = mesh_.vertices[t[0]];
    tri.e1 = mesh_.vertices[t[1]] - tri.v0;
    tri.e2 = mesh_.vertices[t[2]] - tri.v0;
    tri.index = index;
    triangles_.push_back(tri);
  }
}

int MeshSurface::Build(std::vector<int>& order, int begin, int end, int depth) {
  if (depth > kMaxBvhDepth)
    throw std::logic_error("MeshSurface: BVH deeper than its traversal stack");  // our bug
  const int node_index = static_cast<int>(nodes_.size());
  nodes_.emplace_back();
  Eigen::AlignedBox3d box;
  Eigen::AlignedBox3d centroids;
  for (int i = begin; i < end; ++i) {
    const auto& t = mesh_.triangles[order[i]];
    Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
    for (const int v : t) {
      box.extend(mesh_.vertices[v]);
      centroid += mesh_.vertices[v];
    }
    centroids.extend(centroid / 3.0);
  }
  for (int k = 0; k < 3; ++k) {
    nodes_[node_index].lo[k] = box.min()[k];
    nodes_[node_index].hi[k] = box.max()[k];
  }
  const int count = end - begin;
  if (count <= kMaxLeafTriangles) {
    nodes_[node_index].first_or_right = begin;
    nodes_[node_index].count = count;
    return node_index;
  }
  int axis = 0;
  centroids.sizes().maxCoeff(&axis);
  const int mid = begin + count / 2;
  auto centroid_along = [this, axis](int tri) {
    const auto& t = mesh_.triangles[tri];
    return mesh_.vertices[t[0]][axis] + mesh_.vertices[t[1]][axis] + mesh_.vertices[t[2]][axis];
  };
  std::nth_element(order.begin() + begin, order.begin() + mid, order.begin() + end,
                   [&](int a, int b) { return centroid_along(a) < centroid_along(b); });
  Build(order, begin, mid, depth + 1);  // left child lands at node_index + 1
  const int right = Build(order, mid, end, depth + 1);
  nodes_[node_index].first_or_right = right;
  nodes_[node_index].count = 0;
  nodes_[node_index].axis = axis;
  return node_index;
}

bool MeshSurface::HitTriangle(const Triangle& tri, const geometry::Ray& ray, double* best,
                              double* u, double* v) {
  const Eigen::Vector3d p = ray.direction.cross(tri.e2);
  const double det = tri.e1.dot(p);
  if (std::abs(det) < 1e-300) return false;
  const double inv_det = 1.0 / det;
  const Eigen::Vector3d s = ray.origin - tri.v0;
  const double bu = s.dot(p) * inv_det;
  if (bu < -kEdgeSlack || bu > 1.0 + kEdgeSlack) return false;
  const Eigen::Vector3d q = s.cross(tri.e1);
  const double bv = ray.direction.dot(q) * inv_det;
  if (bv < -kEdgeSlack || bu + bv > 1.0 + kEdgeSlack) return false;
  const double t = tri.e2.dot(q) * inv_det;
  if (!(t > kMinHitDistanceMm && t < *best)) return false;
  *best = t;
  *u = bu;
  *v = bv;
  return true;
}

Hit MeshSurface::MakeHit(const geometry::Ray& ray, int slot, double t, double u, double v) const {
  const Triangle& tri = triangles_[slot];
  const auto& idx = mesh_.triangles[tri.index];
  Hit hit;
  hit.distance = t;
  hit.point = ray.At(t);
  hit.geometric_normal = tri.e1.cross(tri.e2).normalized();
  const Eigen::Vector3d n = (1.0 - u - v) * vertex_normals_[idx[0]] + u * vertex_normals_[idx[1]] +
                            v * vertex_normals_[idx[2]];
  const double length = n.norm();
  hit.normal = length > 1e-12 ? Eigen::Vector3d(n / length) : hit.geometric_normal;
  // Keep the shading normal on the facet's front side.
  if (hit.normal.dot(hit.geometric_normal) < 0.0) hit.normal = hit.geometric_normal;
  return hit;
}

std::optional<Hit> MeshSurface::Intersect(const geometry::Ray& ray, double max_distance) const {
  double inv[3];
  bool negative[3];
  for (int k = 0; k < 3; ++k) {
    const double d = ray.direction[k];
    inv[k] = d != 0.0 ? 1.0 / d : std::copysign(std::numeric_limits<double>::infinity(), d);
    negative[k] = inv[k] < 0.0;
  }
  const double origin[3] = {ray.origin.x(), ray.origin.y(), ray.origin.z()};
  double best = max_distance;
  int best_slot = -1;
  double best_u = 0.0, best_v = 0.0;
  int stack[kMaxBvhDepth + 4];
  int top = 0;
  stack[top++] = 0;
  while (top > 0) {
    const Node& node = nodes_[stack[--top]];
    // Slab test against the node's box.
    double t_enter = kMinHitDistanceMm;
    double t_exit = best;
    bool miss = false;
    for (int k = 0; k < 3 && !miss; ++k) {
      double t0 = (node.lo[k] - origin[k]) * inv[k];
      double t1 = (node.hi[k] - origin[k]) * inv[k];
      if (negative[k]) std::swap(t0, t1);
      // NaN (origin on a slab of a parallel ray) compares false: keep the interval.
      if (t0 > t_enter) t_enter = t0;
      if (t1 < t_exit) t_exit = t1;
      miss = t_enter > t_exit;
    }
    if (miss) continue;
    if (node.count > 0) {
      for (int i = node.first_or_right; i < node.first_or_right + node.count; ++i) {
        double u = 0.0, v = 0.0;
        if (HitTriangle(triangles_[i], ray, &best, &u, &v)) {
          best_slot = i;
          best_u = u;
          best_v = v;
        }
      }
      continue;
    }
    const int left = static_cast<int>(&node - nodes_.data()) + 1;
    const int right = node.first_or_right;
    // Visit the child nearer along the split axis first (pushed last).
    if (negative[node.axis]) {
      stack[top++] = left;
      stack[top++] = right;
    } else {
      stack[top++] = right;
      stack[top++] = left;
    }
  }
  if (best_slot < 0) return std::nullopt;
  return MakeHit(ray, best_slot, best, best_u, best_v);
}

std::optional<Hit> MeshSurface::IntersectBruteForce(const geometry::Ray& ray,
                                                    double max_distance) const {
  double best = max_distance;
  int best_slot = -1;
  double best_u = 0.0, best_v = 0.0;
  for (int i = 0; i < static_cast<int>(triangles_.size()); ++i) {
    double u = 0.0, v = 0.0;
    if (HitTriangle(triangles_[i], ray, &best, &u, &v)) {
      best_slot = i;
      best_u = u;
      best_v = v;
    }
  }
  if (best_slot < 0) return std::nullopt;
  return MakeHit(ray, best_slot, best, best_u, best_v);
}

}  // namespace bsls::simulator
