#include "bsls/reconstruction/surface_mesh_builder.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <optional>
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

// The median of the samples of strips p - kSpacingStrips .. p + kSpacingStrips
// (`samples` by strip), so that one or two strips lying wholly across a depth
// jump do not set their own reference; nullopt when strip p has none.
std::optional<double> LocalSpacing(const std::map<int, std::vector<double>>& samples, int p) {
  const auto own = samples.find(p);
  if (own == samples.end() || own->second.empty()) return std::nullopt;
  std::vector<double> around;
  for (int k = p - kSpacingStrips; k <= p + kSpacingStrips; ++k)
    if (const auto it = samples.find(k); it != samples.end())
      around.insert(around.end(), it->second.begin(), it->second.end());
  return Median(std::move(around));
}

// What both strip methods share: the lines' vertices and where they may go.
struct StripInput {
  const std::vector<TriangulatedLine>& lines;
  const std::vector<RowIndex>& rows;
  const std::map<int, int>& line_of_p;      // p -> index into lines
  const std::vector<bool>& along_ok;        // edge (v, v + 1) usable
  const std::vector<Eigen::Vector3d>& pos;  // every vertex, line by line
  const std::vector<int>& line_of_vertex;   // its p
  const MeshParams& params;

  double Length(int a, int b) const { return (pos[a] - pos[b]).norm(); }
  double SquaredLength(int a, int b) const { return (pos[a] - pos[b]).squaredNorm(); }
};

// Thesis 5.2.1: the quads of samples on the same rows, split along the
// shorter diagonal, unless an edge between the lines is longer than
// max_across_ratio times the local spacing (median row-aligned edge).
template <typename AddFace>
void PairRows(const StripInput& in, const AddFace& add_face, MeshReport* r) {
  std::map<int, std::vector<double>> strip_edges;
  for (const auto& [p, la] : in.line_of_p) {
    const auto next = in.line_of_p.find(p + 1);
    if (next == in.line_of_p.end()) continue;
    const RowIndex& ra = in.rows[la];
    const RowIndex& rb = in.rows[next->second];
    std::vector<double>& edges = strip_edges[p];
    for (std::size_t i = 0; i < in.lines[la].vertices.size(); ++i) {
      const int j = rb.Local(in.lines[la].vertices[i].row);
      if (j >= 0) edges.push_back(in.Length(ra.Global(static_cast<int>(i)), rb.Global(j)));
    }
  }
  for (const auto& [p, la] : in.line_of_p) {
    const auto next = in.line_of_p.find(p + 1);
    if (next == in.line_of_p.end()) continue;
    const TriangulatedLine& a = in.lines[la];
    const RowIndex& ra = in.rows[la];
    const RowIndex& rb = in.rows[next->second];
    const std::optional<double> spacing = LocalSpacing(strip_edges, p);
    if (!spacing) continue;
    const double max_across = in.params.max_across_ratio * *spacing;
    for (std::size_t i = 0; i < a.vertices.size(); ++i) {
      const int row = a.vertices[i].row;
      const int j = rb.Local(row), j1 = rb.Local(row + 1);
      if (j < 0 || j1 < 0 || ra.Local(row + 1) < 0) continue;
      const int a0 = ra.Global(static_cast<int>(i)), a1 = a0 + 1;
      const int b0 = rb.Global(j), b1 = rb.Global(j1);
      if (!in.along_ok[a0] || !in.along_ok[b0]) {
        ++r->dropped_along;
        continue;
      }
      // Two triangles per quad; split along the shorter diagonal.
      Eigen::Vector3i tris[2];
      if (in.Length(a0, b1) <= in.Length(a1, b0)) {
        tris[0] = {a0, a1, b1};
        tris[1] = {a0, b1, b0};
      } else {
        tris[0] = {a0, a1, b0};
        tris[1] = {a1, b1, b0};
      }
      for (const Eigen::Vector3i& t : tris) {
        // Every triangle has two edges between the lines; both must be short.
        bool ok = true;
        for (int k = 0; k < 3; ++k) {
          const int u = t[k], w = t[(k + 1) % 3];
          if (in.line_of_vertex[u] != in.line_of_vertex[w] && in.Length(u, w) > max_across)
            ok = false;
        }
        if (!ok) {
          ++r->dropped_across;
          continue;
        }
        add_face(t);
      }
    }
  }
}

// For every vertex of line `from` (global indices first .. first + count - 1),
// the distance to the nearest vertex of line `to` (to_first .. + to_count - 1),
// found by descent from the previous vertex's nearest (the lines run side by
// side), checked over a window around it.
std::vector<double> NearestAcross(const StripInput& in, int first, int count, int to_first,
                                  int to_count) {
  constexpr int kWindow = 8;
  std::vector<double> nearest(static_cast<std::size_t>(count));
  int k = 0;
  for (int i = 0; i < count; ++i) {
    const int v = first + i;
    // Compared squared: the nearest is the same, one root taken.
    auto d2 = [&](int w) { return in.SquaredLength(v, to_first + w); };
    while (k + 1 < to_count && d2(k + 1) <= d2(k)) ++k;
    while (k > 0 && d2(k - 1) < d2(k)) --k;
    double best = d2(k);
    int best_k = k;
    for (int w = std::max(0, k - kWindow); w <= std::min(to_count - 1, k + kWindow); ++w)
      if (const double d = d2(w); d < best) best = d, best_k = w;
    k = best_k;
    nearest[static_cast<std::size_t>(i)] = std::sqrt(best);
  }
  return nearest;
}

// Each strip stitched (Christiansen and Sederberg 1978): from the lines'
// first vertices on, the next triangle takes the next vertex of whichever
// line makes the new edge between the lines shorter. A step across a gap in
// a line (a missing row, a depth jump along it) makes no triangle; nor does
// one whose edges between the lines are longer than max_across_ratio times
// the local spacing (the median nearest distance between neighbouring
// lines: a depth jump or shadow) or max_stitch_ratio times the nearest
// distance at either of their ends (a fan from a line's end).
template <typename AddFace>
void StitchStrips(const StripInput& in, const AddFace& add_face, MeshReport* r) {
  struct Strip {
    int a = 0, na = 0, b = 0, nb = 0;  // first global vertex and count of lines p, p + 1
    std::vector<double> near_a, near_b;
  };
  std::map<int, Strip> strips;
  std::map<int, std::vector<double>> nearest;
  for (const auto& [p, la] : in.line_of_p) {
    const auto next = in.line_of_p.find(p + 1);
    if (next == in.line_of_p.end()) continue;
    Strip s;
    s.na = static_cast<int>(in.lines[la].vertices.size());
    s.nb = static_cast<int>(in.lines[next->second].vertices.size());
    if (s.na == 0 || s.nb == 0) continue;
    s.a = in.rows[la].Global(0);
    s.b = in.rows[next->second].Global(0);
    s.near_a = NearestAcross(in, s.a, s.na, s.b, s.nb);
    s.near_b = NearestAcross(in, s.b, s.nb, s.a, s.na);
    std::vector<double>& samples = nearest[p];
    samples.insert(samples.end(), s.near_a.begin(), s.near_a.end());
    samples.insert(samples.end(), s.near_b.begin(), s.near_b.end());
    strips.emplace(p, std::move(s));
  }
  for (const auto& entry : strips) {
    // Named, not a structured binding: the lambdas below capture them
    // (clang before 16 refuses to capture a structured binding).
    const int p = entry.first;
    const Strip& s = entry.second;
    // Every strip here has samples of its own (both lines have vertices).
    const double max_across = in.params.max_across_ratio * LocalSpacing(nearest, p).value();
    // Edge (a + i, b + j) between the lines: short enough to take part.
    const auto across_ok = [&](int i, int j) {
      const double d = in.Length(s.a + i, s.b + j);
      return d <= max_across &&
             d <= in.params.max_stitch_ratio * std::min(s.near_a[i], s.near_b[j]);
    };
    int i = 0, j = 0;
    while (i + 1 < s.na || j + 1 < s.nb) {
      const double step_a =
          i + 1 < s.na ? in.Length(s.a + i + 1, s.b + j) : std::numeric_limits<double>::infinity();
      const double step_b =
          j + 1 < s.nb ? in.Length(s.a + i, s.b + j + 1) : std::numeric_limits<double>::infinity();
      // The triangle of the step along `along` (its next sample `next`),
      // with the other line's sample `apex`, if its edges may be used.
      const auto step = [&](int along, int next, int apex, int i_next, int j_next) {
        if (!in.along_ok[along])
          ++r->dropped_along;
        else if (!across_ok(i, j) || !across_ok(i_next, j_next))
          ++r->dropped_across;
        else
          add_face({along, next, apex});
      };
      if (step_a <= step_b) {
        step(s.a + i, s.a + i + 1, s.b + j, i + 1, j);
        ++i;
      } else {
        step(s.b + j, s.b + j + 1, s.a + i, i, j + 1);
        ++j;
      }
    }
  }
}

}  // namespace

bool MeshParams::IsValid(std::string* error) const {
  if (!std::isfinite(max_across_ratio) || max_across_ratio <= 1.0)
    return Fail(error, "mesh: max_across_ratio must be finite and > 1");
  if (!std::isfinite(max_along_ratio) || max_along_ratio <= 1.0)
    return Fail(error, "mesh: max_along_ratio must be finite and > 1");
  if (!std::isfinite(min_along_jump_mm) || min_along_jump_mm < 0.0)
    return Fail(error, "mesh: min_along_jump_mm must be finite and >= 0");
  if (!std::isfinite(max_stitch_ratio) || max_stitch_ratio < 1.0)
    return Fail(error, "mesh: max_stitch_ratio must be finite and >= 1");
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

  // Adds triangle t, wound counter-clockwise seen from the camera.
  const auto add_face = [&](Eigen::Vector3i t) {
    const Eigen::Vector3d n = (pos[t[1]] - pos[t[0]]).cross(pos[t[2]] - pos[t[0]]);
    const Eigen::Vector3d centroid = (pos[t[0]] + pos[t[1]] + pos[t[2]]) / 3.0;
    if (n.dot(camera_centre - centroid) < 0.0) std::swap(t[1], t[2]);
    mesh.faces.push_back(t);
  };
  const StripInput in{lines, rows, line_of_p, along_ok, pos, mesh.line, params};
  if (params.strips == StripMethod::kStitched)
    StitchStrips(in, add_face, &r);
  else
    PairRows(in, add_face, &r);

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
