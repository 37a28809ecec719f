// Surfaces of the simulator sampled into geometry::SurfaceMesh for the tests
// of the stages that work on meshes (measurement, joining), without the
// reconstruction stage: on a regular x-y grid (vertical rays), or along the
// projected stripes as the BSLS rig samples a face (rays from the projector
// through the slide's vertical lines, one sample per slide step along a line).
//
// Frame and units: world frame of contracts section 3, millimetres.
// Noise: Gaussian, along world z, seeded; uncertainty_mm holds its sigma.
#ifndef BSLS_TESTING_SURFACE_SAMPLING_H_
#define BSLS_TESTING_SURFACE_SAMPLING_H_

#include <Eigen/Core>
#include <cmath>
#include <cstdint>
#include <numbers>
#include <vector>

#include "bsls/geometry/surface_mesh.h"
#include "bsls/pattern/brick_pattern.h"
#include "bsls/simulator/surface.h"

namespace bsls::testing {

// A regular grid of vertical rays from above.
struct GridSampling {
  double x_min_mm = -50.0, x_max_mm = 50.0;  // inclusive range, world x
  double y_min_mm = -50.0, y_max_mm = 50.0;  // inclusive range, world y
  double step_x_mm = 1.0, step_y_mm = 1.0;   // > 0
  double noise_mm = 0.0;                     // sigma along z, >= 0
  std::uint32_t seed = 1;
};

// The stripes of one side as the thesis rig projects them (projector at
// (0, 0, 730) mm looking down, 128 slide pitches focal length: lines 5.7 mm
// apart at z = 0, closer together above it).
struct StripeSampling {
  pattern::Side side = pattern::Side::kLeft;
  int lines = 20;                     // p = 0 .. lines-1; p grows towards -x (left) or +x (right)
  double slide_step_d = 0.0877;       // step along a line in slide pitches (0.5 mm at z = 0)
  double slide_half_height_d = 18.0;  // lines span slide t in [-h, h]
  double projector_height_mm = 730.0;
  double focal_d = 128.0;
  double noise_mm = 0.0;  // sigma along z, >= 0
  std::uint32_t seed = 1;
};

// Vertices where the rays hit `surface`, triangles between neighbouring
// samples (both diagonals' triangles kept when 3 of 4 corners exist), faces
// counter-clockwise seen from +z, area-weighted normals; `line` empty.
geometry::SurfaceMesh SampleGrid(const simulator::Surface& surface, const GridSampling& params);

// Samples along each stripe; `line` holds p, triangles join lines p and p+1
// sample by sample (the same slide row on both lines).
geometry::SurfaceMesh SampleStripes(const simulator::Surface& surface,
                                    const StripeSampling& params);

// A circle of `radius` (mm) around `centre` as a polygon of `vertices`
// corners: the region a test measures a lesion in.
inline std::vector<Eigen::Vector2d> Circle(const Eigen::Vector2d& centre, double radius,
                                           int vertices = 64) {
  std::vector<Eigen::Vector2d> polygon;
  for (int i = 0; i < vertices; ++i) {
    const double angle = 2.0 * std::numbers::pi * i / vertices;
    polygon.push_back(centre + radius * Eigen::Vector2d(std::cos(angle), std::sin(angle)));
  }
  return polygon;
}

}  // namespace bsls::testing

#endif  // BSLS_TESTING_SURFACE_SAMPLING_H_
