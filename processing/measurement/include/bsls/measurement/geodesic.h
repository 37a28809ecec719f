// Along-the-surface (geodesic) distance between two surface points.
//
// Method: shortest path on a Steiner graph (Lanthier, Maheshwari and Sack
// 2001; Aleksandrov et al.): every mesh edge carries k evenly spaced Steiner
// points, and every pair of points (vertices, Steiner points, the two end
// points) on the boundary of a common face is joined by the straight segment
// across that face. A* with the straight-line distance as heuristic finds the
// shortest path in this graph. Paths may cross faces anywhere along the
// Steiner points instead of following mesh edges (plain Dijkstra on edges
// overestimates by up to ~8% on a grid), and the result converges to the
// exact mesh geodesic as k grows: the excess is bounded by a term in
// (edge length / k). docs/measurement.md gives the error measured on a ball.
//
// Discretisation estimate: |d(k) - d(ceil(k/2))|, an upper bound of the
// remaining graph error when the error decreases at least as 1/k.
//
// Frame and units: world millimetres; end points given by world (x, y) and
// lifted onto the surface (SurfaceQuery::Above).
// Errors: MeasurementError naming the input and the reason.
#ifndef BSLS_MEASUREMENT_GEODESIC_H_
#define BSLS_MEASUREMENT_GEODESIC_H_

#include <Eigen/Core>
#include <string>
#include <vector>

#include "bsls/measurement/measures.h"
#include "bsls/measurement/surface_query.h"

namespace bsls::measurement {

struct GeodesicParams {
  int steiner_points_per_edge = 6;      // k, in [0, 64]; 0 is Dijkstra on the edges
  bool estimate_discretisation = true;  // also solve with ceil(k/2) for the error estimate

  // True when the numbers are in range; otherwise names the field.
  bool IsValid(std::string* error) const;
};

struct GeodesicResult {
  // Length along the surface (mm); uncertainty: end points' sigma and the
  // discretisation estimate in quadrature.
  Measured distance_mm;
  Measured straight_mm;               // 3-D chord between the end points, for comparison
  double discretisation_mm = 0.0;     // |d(k) - d(ceil(k/2))|, 0 when not estimated
  std::vector<Eigen::Vector3d> path;  // world mm, from start to end
};

// Geodesic distance between the surface points over `a_xy` and `b_xy`.
// Throws MeasurementError when a point is outside the surface, the two are
// not connected by the mesh, or the params are invalid.
GeodesicResult GeodesicDistance(const SurfaceQuery& surface, const Eigen::Vector2d& a_xy,
                                const Eigen::Vector2d& b_xy, const GeodesicParams& params = {});

}  // namespace bsls::measurement

#endif  // BSLS_MEASUREMENT_GEODESIC_H_
