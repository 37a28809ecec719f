#include "bsls/reconstruction/surface_mesh_builder.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <map>
#include <stdexcept>

namespace bsls::reconstruction {
namespace {

// Strips on either side of a strip whose edges set its local spacing.
constexpr int kSpacingStrips = 2;

bool Fail(std::string* error, const std::string& why) {
  if (error) *error = why;
  return false;
}

double Median(std::vector<double> values) {
  if (values.empty()) return 0.0;
  const auto middle = values.begin() + values.size() / 2;
  std::nth_element(values.begin(), middle, values.end());
  return *middle;
}

// Vertex index by image row for one line.
class RowIndex {
 public:
  RowIndex(const TriangulatedLine& line, int first_vertex) : first_vertex_(first_vertex) {
    if (line.vertices.empty()) return;
    first_row_ = line.vertices.front().row;
    local_.assign(line.vertices.back().row - first_row_ + 1, -1);
    for (std::size_t i = 0; i < line.vertices.size(); ++i)
      local_[line.vertices[i].row - first_row_] = static_cast<int>(i);
  }
  // Local index of the sample on `row`, or -1.
  int Local(int row) const {
    const int k = row - first_row_;
    return k >= 0 && k < static_cast<int>(local_.size()) ? local_[k] : -1;
  }
  int Global(int local) const { return first_vertex_ + local; }

 private:
  int first_vertex_ = 0;
  int first_row_ = 0;
  std::vector<int> local_;
};

}  // namespace

bool MeshParams::IsValid(std::string* error) const {
  if (!std::isfinite(max_across_ratio) || max_across_ratio <= 1.0)
    return Fail(error, "mesh: max_across_ratio must be finite and > 1");
  if (!std::isfinite(max_along_ratio) || max_along_ratio <= 1.0)
    return Fail(error, "mesh: max_along_ratio must be finite and > 1");
  if (!std::isfinite(min_along_jump_mm) || min_along_jump_mm < 0.0)
    return Fail(error, "mesh: min_along_jump_mm must be finite and >= 0");
  return true;
}

geometry::SurfaceMesh BuildSurfaceMesh(const std::vector<TriangulatedLine>& lines,
                                       const Eigen::Vector3d& camera_centre,
                                       const MeshParams& params, MeshReport* report) {
  std::string why;
  if (!params.IsValid(&why)) throw std::invalid_argument(why);
  MeshReport r;
  geometry::SurfaceMesh mesh;
  std::vector<RowIndex> rows;
  std::map<int, int> line_of_p;  // p -> index into lines
  // Along-line edge (i, i + 1) of each vertex usable for triangles.
  std::vector<bool> along_ok;
  for (std::size_t l = 0; l < lines.size(); ++l) {
    const TriangulatedLine& line = lines[l];
    for (std::size_t i = 1; i < line.vertices.size(); ++i)
      if (line.vertices[i].row <= line.vertices[i - 1].row)
        throw std::invalid_argument("mesh: rows of line " + std::to_string(line.p) +
                                    " are not strictly increasing");
    if (!line_of_p.emplace(line.p, static_cast<int>(l)).second)
      throw std::invalid_argument("mesh: line " + std::to_string(line.p) + " given twice");
    rows.emplace_back(line, static_cast<int>(mesh.positions.size()));
    std::vector<double> steps;
    for (std::size_t i = 0; i + 1 < line.vertices.size(); ++i)
      if (line.vertices[i + 1].row == line.vertices[i].row + 1)
        steps.push_back((line.vertices[i + 1].position - line.vertices[i].position).norm());
    const double max_step =
        std::max(params.min_along_jump_mm, params.max_along_ratio * Median(steps));
    for (std::size_t i = 0; i < line.vertices.size(); ++i) {
      const LineVertex& v = line.vertices[i];
      mesh.positions.push_back(v.position);
      mesh.uncertainty_mm.push_back(v.sigma_mm);
      mesh.line.push_back(line.p);
      mesh.flags.push_back(v.flags);
      const bool next = i + 1 < line.vertices.size() && line.vertices[i + 1].row == v.row + 1;
      along_ok.push_back(next && (line.vertices[i + 1].position - v.position).norm() <= max_step);
    }
  }
  const auto& pos = mesh.positions;
  const auto length = [&pos](int a, int b) { return (pos[a] - pos[b]).norm(); };

  // Row-aligned edges between the lines of each strip (p, p + 1).
  std::map<int, std::vector<double>> strip_edges;
  for (const auto& [p, la] : line_of_p) {
    const auto next = line_of_p.find(p + 1);
    if (next == line_of_p.end()) continue;
    const RowIndex& ra = rows[la];
    const RowIndex& rb = rows[next->second];
    std::vector<double>& edges = strip_edges[p];
    for (std::size_t i = 0; i < lines[la].vertices.size(); ++i) {
      const int j = rb.Local(lines[la].vertices[i].row);
      if (j >= 0) edges.push_back(length(ra.Global(static_cast<int>(i)), rb.Global(j)));
    }
  }
  for (const auto& [p, la] : line_of_p) {
    const auto next = line_of_p.find(p + 1);
    if (next == line_of_p.end()) continue;
    const int lb = next->second;
    const TriangulatedLine& a = lines[la];
    const RowIndex& ra = rows[la];
    const RowIndex& rb = rows[lb];
    // The local spacing: the median row-aligned edge of this strip and the
    // strips up to kSpacingStrips on either side, so that one or two strips
    // lying wholly across a depth jump do not set their own reference.
    std::vector<double> around;
    for (int k = p - kSpacingStrips; k <= p + kSpacingStrips; ++k)
      if (const auto it = strip_edges.find(k); it != strip_edges.end())
        around.insert(around.end(), it->second.begin(), it->second.end());
    if (strip_edges[p].empty()) continue;
    const double max_across = params.max_across_ratio * Median(around);
    for (std::size_t i = 0; i < a.vertices.size(); ++i) {
      const int row = a.vertices[i].row;
      const int j = rb.Local(row), j1 = rb.Local(row + 1);
      if (j < 0 || j1 < 0 || ra.Local(row + 1) < 0) continue;
      const int a0 = ra.Global(static_cast<int>(i)), a1 = a0 + 1;
      const int b0 = rb.Global(j), b1 = rb.Global(j1);
      if (!along_ok[a0] || !along_ok[b0]) {
        ++r.dropped_along;
        continue;
      }
      // Thesis 5.2.1: two triangles per quad; split along the shorter diagonal.
      Eigen::Vector3i tris[2];
      if (length(a0, b1) <= length(a1, b0)) {
        tris[0] = {a0, a1, b1};
        tris[1] = {a0, b1, b0};
      } else {
        tris[0] = {a0, a1, b0};
        tris[1] = {a1, b1, b0};
      }
      for (Eigen::Vector3i t : tris) {
        // Every triangle has two edges between the lines; both must be short.
        bool ok = true;
        for (int k = 0; k < 3; ++k) {
          const int u = t[k], w = t[(k + 1) % 3];
          if (mesh.line[u] != mesh.line[w] && length(u, w) > max_across) ok = false;
        }
        if (!ok) {
          ++r.dropped_across;
          continue;
        }
        const Eigen::Vector3d n = (pos[t[1]] - pos[t[0]]).cross(pos[t[2]] - pos[t[0]]);
        const Eigen::Vector3d centroid = (pos[t[0]] + pos[t[1]] + pos[t[2]]) / 3.0;
        if (n.dot(camera_centre - centroid) < 0.0) std::swap(t[1], t[2]);
        mesh.faces.push_back(t);
      }
    }
  }

  // Gouraud: the mean of the unit normals of the faces around a vertex.
  std::vector<Eigen::Vector3d> sum(pos.size(), Eigen::Vector3d::Zero());
  for (const Eigen::Vector3i& t : mesh.faces) {
    const Eigen::Vector3d n = (pos[t[1]] - pos[t[0]]).cross(pos[t[2]] - pos[t[0]]);
    const double norm = n.norm();
    if (!(norm > 0.0)) continue;
    for (int k = 0; k < 3; ++k) sum[t[k]] += n / norm;
  }
  mesh.normals.resize(pos.size());
  for (std::size_t v = 0; v < pos.size(); ++v) {
    const double norm = sum[v].norm();
    if (norm > 1e-9) {
      mesh.normals[v] = sum[v] / norm;
    } else {
      const Eigen::Vector3d to_camera = camera_centre - pos[v];
      mesh.normals[v] = to_camera.norm() > 0.0 ? to_camera.normalized() : Eigen::Vector3d::UnitZ();
    }
  }
  r.vertices = static_cast<int>(pos.size());
  r.triangles = static_cast<int>(mesh.faces.size());
  if (report) *report = r;
  return mesh;
}

}  // namespace bsls::reconstruction
