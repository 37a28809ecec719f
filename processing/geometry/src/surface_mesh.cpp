#include "bsls/geometry/surface_mesh.h"

namespace bsls::geometry {
namespace {

bool Fail(std::string* error, const std::string& why) {
  if (error) *error = why;
  return false;
}

// True when an attribute is absent or has one entry per vertex.
template <typename T>
bool SizeFits(const std::vector<T>& attribute, std::size_t vertices) {
  return attribute.empty() || attribute.size() == vertices;
}

}  // namespace

bool SurfaceMesh::IsValid(std::string* error) const {
  const std::size_t n = positions.size();
  const std::string count = " entries for " + std::to_string(n) + " vertices";
  if (!SizeFits(normals, n))
    return Fail(error, "surface mesh: normals has " + std::to_string(normals.size()) + count);
  if (!SizeFits(uncertainty_mm, n))
    return Fail(
        error, "surface mesh: uncertainty_mm has " + std::to_string(uncertainty_mm.size()) + count);
  if (!SizeFits(line, n))
    return Fail(error, "surface mesh: line has " + std::to_string(line.size()) + count);
  if (!SizeFits(flags, n))
    return Fail(error, "surface mesh: flags has " + std::to_string(flags.size()) + count);
  for (std::size_t f = 0; f < faces.size(); ++f) {
    const Eigen::Vector3i& face = faces[f];
    for (int k = 0; k < 3; ++k)
      if (face[k] < 0 || static_cast<std::size_t>(face[k]) >= n)
        return Fail(error, "surface mesh: face " + std::to_string(f) + " refers to vertex " +
                               std::to_string(face[k]) + " of " + std::to_string(n));
    if (face[0] == face[1] || face[1] == face[2] || face[0] == face[2])
      return Fail(error, "surface mesh: face " + std::to_string(f) + " repeats a vertex");
  }
  return true;
}

}  // namespace bsls::geometry
