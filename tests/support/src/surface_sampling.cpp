#include "bsls/testing/surface_sampling.h"

#include <Eigen/Geometry>
#include <cmath>
#include <limits>
#include <optional>
#include <random>
#include <vector>

namespace bsls::testing {
namespace {

constexpr double kAboveEverythingMm = 1.0e5;

// Lattice of optional samples (columns i, rows j) into a mesh.
geometry::SurfaceMesh Triangulate(
    const std::vector<std::vector<std::optional<Eigen::Vector3d>>>& lattice,
    const std::vector<int>& column_labels, double noise_mm, std::uint32_t seed) {
  geometry::SurfaceMesh mesh;
  std::mt19937 random(seed);
  std::normal_distribution<double> gauss(0.0, 1.0);
  std::vector<std::vector<int>> index(lattice.size());
  for (std::size_t i = 0; i < lattice.size(); ++i) {
    index[i].assign(lattice[i].size(), -1);
    for (std::size_t j = 0; j < lattice[i].size(); ++j) {
      if (!lattice[i][j]) continue;
      Eigen::Vector3d p = *lattice[i][j];
      if (noise_mm > 0.0) p.z() += noise_mm * gauss(random);
      index[i][j] = static_cast<int>(mesh.positions.size());
      mesh.positions.push_back(p);
      mesh.uncertainty_mm.push_back(static_cast<float>(noise_mm));
      if (!column_labels.empty()) mesh.line.push_back(column_labels[i]);
    }
  }
  auto add = [&](int a, int b, int c) {
    if (a < 0 || b < 0 || c < 0) return;
    const Eigen::Vector3d n =
        (mesh.positions[b] - mesh.positions[a]).cross(mesh.positions[c] - mesh.positions[a]);
    if (n.z() >= 0.0)
      mesh.faces.emplace_back(a, b, c);
    else
      mesh.faces.emplace_back(a, c, b);
  };
  for (std::size_t i = 0; i + 1 < lattice.size(); ++i) {
    const std::size_t rows = std::min(lattice[i].size(), lattice[i + 1].size());
    for (std::size_t j = 0; j + 1 < rows; ++j) {
      const int a = index[i][j], b = index[i + 1][j], c = index[i + 1][j + 1], d = index[i][j + 1];
      const int present = (a >= 0) + (b >= 0) + (c >= 0) + (d >= 0);
      if (present == 4) {
        add(a, b, c);
        add(a, c, d);
      } else if (present == 3) {
        if (a < 0) add(b, c, d);
        if (b < 0) add(a, c, d);
        if (c < 0) add(a, b, d);
        if (d < 0) add(a, b, c);
      }
    }
  }
  mesh.normals.assign(mesh.positions.size(), Eigen::Vector3d::Zero());
  for (const Eigen::Vector3i& f : mesh.faces) {
    const Eigen::Vector3d n = (mesh.positions[f[1]] - mesh.positions[f[0]])
                                  .cross(mesh.positions[f[2]] - mesh.positions[f[0]]);
    for (int k = 0; k < 3; ++k) mesh.normals[f[k]] += n;
  }
  for (Eigen::Vector3d& n : mesh.normals)
    n = n.norm() > 0.0 ? Eigen::Vector3d(n.normalized()) : Eigen::Vector3d::UnitZ();
  return mesh;
}

}  // namespace

geometry::SurfaceMesh SampleGrid(const simulator::Surface& surface, const GridSampling& params) {
  const int nx =
      static_cast<int>(std::floor((params.x_max_mm - params.x_min_mm) / params.step_x_mm + 1e-9)) +
      1;
  const int ny =
      static_cast<int>(std::floor((params.y_max_mm - params.y_min_mm) / params.step_y_mm + 1e-9)) +
      1;
  std::vector<std::vector<std::optional<Eigen::Vector3d>>> lattice(nx);
  for (int i = 0; i < nx; ++i) {
    lattice[i].resize(ny);
    for (int j = 0; j < ny; ++j) {
      geometry::Ray ray;
      ray.origin = {params.x_min_mm + i * params.step_x_mm, params.y_min_mm + j * params.step_y_mm,
                    kAboveEverythingMm};
      ray.direction = -Eigen::Vector3d::UnitZ();
      if (auto hit = surface.Intersect(ray, std::numeric_limits<double>::infinity()))
        lattice[i][j] = hit->point;
    }
  }
  return Triangulate(lattice, {}, params.noise_mm, params.seed);
}

geometry::SurfaceMesh SampleStripes(const simulator::Surface& surface,
                                    const StripeSampling& params) {
  const double sign = params.side == pattern::Side::kLeft ? -1.0 : 1.0;
  const int rows =
      static_cast<int>(std::floor(2.0 * params.slide_half_height_d / params.slide_step_d)) + 1;
  std::vector<std::vector<std::optional<Eigen::Vector3d>>> lattice(params.lines);
  std::vector<int> labels(params.lines);
  for (int p = 0; p < params.lines; ++p) {
    labels[p] = p;
    lattice[p].resize(rows);
    for (int j = 0; j < rows; ++j) {
      const double t = -params.slide_half_height_d + j * params.slide_step_d;
      geometry::Ray ray;
      ray.origin = {0.0, 0.0, params.projector_height_mm};
      // Slide s towards world +x, t towards world -y (scene.h).
      ray.direction =
          Eigen::Vector3d(sign * p / params.focal_d, -t / params.focal_d, -1.0).normalized();
      if (auto hit = surface.Intersect(ray, std::numeric_limits<double>::infinity()))
        lattice[p][j] = hit->point;
    }
  }
  return Triangulate(lattice, labels, params.noise_mm, params.seed);
}

}  // namespace bsls::testing
