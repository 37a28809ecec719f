// The simulated face sampled along the stripes of each side, as the rig
// samples it, shared by the joining tests (loaded once per test program).
#ifndef BSLS_TESTS_JOINING_FACE_FIXTURE_H_
#define BSLS_TESTS_JOINING_FACE_FIXTURE_H_

#include <Eigen/Geometry>
#include <cstdint>
#include <filesystem>
#include <memory>

#include "bsls/geometry/surface_mesh.h"
#include "bsls/simulator/mesh.h"
#include "bsls/simulator/scene.h"
#include "bsls/testing/build_paths.h"
#include "bsls/testing/surface_sampling.h"

namespace bsls::joining::test {

// The bundled face (simulator/data), built once.
inline const simulator::Surface& Face() {
  static const std::shared_ptr<const simulator::Surface> face = [] {
    simulator::FaceModelParams params;
    params.obj_path = bsls::testing::TestDataDir() / "canonical_face_model.obj";
    return std::make_shared<simulator::MeshSurface>(simulator::LoadFaceMesh(params), "face");
  }();
  return *face;
}

// The right side samples its lines at a slightly different step than the
// left, so that the two reference lines share no vertex (as two rigs would).
constexpr double kRightStepScale = 1.07;

// One side's stripes on the face, with Gaussian noise along z (sigma noise_mm).
inline geometry::SurfaceMesh SampleSide(pattern::Side side, double noise_mm, std::uint32_t seed) {
  testing::StripeSampling sampling;
  sampling.side = side;
  if (side == pattern::Side::kRight) sampling.slide_step_d *= kRightStepScale;
  sampling.noise_mm = noise_mm;
  sampling.seed = seed;
  return testing::SampleStripes(Face(), sampling);
}

// `mesh` moved by `transform` (positions and normals).
inline geometry::SurfaceMesh Moved(geometry::SurfaceMesh mesh, const Eigen::Isometry3d& transform) {
  for (Eigen::Vector3d& p : mesh.positions) p = transform * p;
  for (Eigen::Vector3d& n : mesh.normals) n = transform.linear() * n;
  return mesh;
}

}  // namespace bsls::joining::test

#endif  // BSLS_TESTS_JOINING_FACE_FIXTURE_H_
