#include "bsls/joining/stitch.h"

#include <algorithm>
#include <cmath>

namespace bsls::joining {
namespace {

// Appends `from`'s attribute entries of the kept vertices, or marks the
// merged attribute unknown when one side lacks it.
template <typename T>
void AppendAttribute(const std::vector<T>& from, const std::vector<int>& kept, std::vector<T>* to,
                     bool* known) {
  if (from.empty()) {
    *known = false;
    return;
  }
  for (int v : kept) to->push_back(from[v]);
}

}  // namespace

bool StitchParams::IsValid(std::string* error) const {
  auto fail = [&](const char* why) {
    if (error) *error = why;
    return false;
  };
  if (!(max_edge_mm > 0.0)) return fail("max_edge_mm must be > 0");
  if (!(max_seam_distance_mm > 0.0)) return fail("max_seam_distance_mm must be > 0");
  return true;
}

StitchResult StitchAlongReferenceLine(const geometry::SurfaceMesh& left,
                                      const geometry::SurfaceMesh& right, int reference_line,
                                      double max_line_gap_mm, const StitchParams& params) {
  StitchResult result;
  geometry::SurfaceMesh& mesh = result.mesh;
  mesh = left;
  result.right_vertex_offset = left.positions.size();

  // Right's vertices off the reference line, renumbered after left's.
  std::vector<int> kept;
  std::vector<int> renumber(right.positions.size(), -1);
  for (std::size_t v = 0; v < right.positions.size(); ++v) {
    if (!right.line.empty() && right.line[v] == reference_line) continue;
    renumber[v] = static_cast<int>(result.right_vertex_offset + kept.size());
    kept.push_back(static_cast<int>(v));
  }
  for (int v : kept) mesh.positions.push_back(right.positions[v]);
  bool normals_known = !left.normals.empty(), uncertainty_known = !left.uncertainty_mm.empty(),
       line_known = !left.line.empty();
  if (normals_known) AppendAttribute(right.normals, kept, &mesh.normals, &normals_known);
  if (uncertainty_known)
    AppendAttribute(right.uncertainty_mm, kept, &mesh.uncertainty_mm, &uncertainty_known);
  if (line_known) AppendAttribute(right.line, kept, &mesh.line, &line_known);
  if (!normals_known) mesh.normals.clear();
  if (!uncertainty_known) mesh.uncertainty_mm.clear();
  if (!line_known) mesh.line.clear();
  if (!left.flags.empty() || !right.flags.empty()) {  // empty flags mean all clear
    if (left.flags.empty()) mesh.flags.assign(left.positions.size(), 0);
    for (int v : kept) mesh.flags.push_back(right.flags.empty() ? 0 : right.flags[v]);
  }
  for (const Eigen::Vector3i& f : right.faces) {
    const Eigen::Vector3i g(renumber[f[0]], renumber[f[1]], renumber[f[2]]);
    if (g.minCoeff() >= 0) mesh.faces.push_back(g);
  }

  // The zipper: left's reference line (a) against right's next line (b), both
  // top to bottom, advancing on the side whose next vertex gives the shorter
  // diagonal.
  const StripeCurve a = StripeCurve::FromMesh(left, reference_line, max_line_gap_mm);
  const StripeCurve b = StripeCurve::FromMesh(right, reference_line + 1, max_line_gap_mm);
  if (a.size() < 2 || b.size() < 2) return result;
  const std::vector<Eigen::Vector3d> left_normals = VertexNormals(left);
  const std::vector<Eigen::Vector3d> right_normals = VertexNormals(right);
  auto add = [&](int ia, int ib, int ic, const Eigen::Vector3d& pa, const Eigen::Vector3d& pb,
                 const Eigen::Vector3d& pc, const Eigen::Vector3d& reference_normal) {
    if ((pb - pa).norm() > params.max_edge_mm || (pc - pb).norm() > params.max_edge_mm ||
        (pa - pc).norm() > params.max_edge_mm) {
      ++result.skipped_zipper_triangles;
      return;
    }
    // a is left of b: (a_i, a_i+1, b_j) and (a_i, b_j+1, b_j) run counter-clockwise
    // seen from the front; the sides' normals confirm it where they are known.
    const Eigen::Vector3d n = (pb - pa).cross(pc - pa);
    if (reference_normal.squaredNorm() > 0.0 && n.dot(reference_normal) < 0.0)
      mesh.faces.emplace_back(ia, ic, ib);
    else
      mesh.faces.emplace_back(ia, ib, ic);
    ++result.zipper_triangles;
  };
  auto normal_at = [](const std::vector<Eigen::Vector3d>& normals, int v) {
    return normals.empty() ? Eigen::Vector3d::Zero() : normals[v];
  };
  std::size_t i = 0, j = 0;
  const auto& pa = a.points();
  const auto& pb = b.points();
  while (i + 1 < a.size() || j + 1 < b.size()) {
    const bool advance_a =
        j + 1 >= b.size() ||
        (i + 1 < a.size() && (pa[i + 1] - pb[j]).squaredNorm() < (pa[i] - pb[j + 1]).squaredNorm());
    const int vb = renumber[b.vertices()[j]];
    const int va = a.vertices()[i];
    const Eigen::Vector3d reference =
        normal_at(left_normals, va) + normal_at(right_normals, b.vertices()[j]);
    if (advance_a) {
      if (a.Joined(i)) {
        add(va, a.vertices()[i + 1], vb, pa[i], pa[i + 1], pb[j], reference);
      } else {
        ++result.skipped_zipper_triangles;
      }
      ++i;
    } else {
      if (b.Joined(j)) {
        add(va, renumber[b.vertices()[j + 1]], vb, pa[i], pb[j + 1], pb[j], reference);
      } else {
        ++result.skipped_zipper_triangles;
      }
      ++j;
    }
  }
  return result;
}

SeamError MeasureSeam(const StripeCurve& left, const StripeCurve& right,
                      const StitchParams& params) {
  SeamError seam;
  double squared = 0.0;
  auto measure = [&](const StripeCurve& from, const StripeCurve& to) {
    for (const Eigen::Vector3d& p : from.points()) {
      const auto closest = to.Closest(p, params.max_seam_distance_mm);
      if (!closest) continue;
      squared += closest->distance_mm * closest->distance_mm;
      seam.max_mm = std::max(seam.max_mm, closest->distance_mm);
      ++seam.samples;
    }
  };
  measure(left, right);
  measure(right, left);
  if (seam.samples > 0) seam.rms_mm = std::sqrt(squared / seam.samples);
  return seam;
}

}  // namespace bsls::joining
