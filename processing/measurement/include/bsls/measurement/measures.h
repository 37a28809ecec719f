// Basic measurements on a reconstructed surface (thesis 7.2, Table 7.2 and
// equation 7.1): heights above the base plane or a fitted reference plane,
// straight distances and areas, each with a 1-sigma uncertainty.
//
// Frame and units: world frame of contracts section 3, millimetres (mm^2 for
// areas). Points are given by their world (x, y) and lifted onto the surface
// (the highest surface point on the vertical line, SurfaceQuery::Above).
//
// Uncertainty model (docs/measurement.md): vertex errors are independent,
// isotropic, 1-sigma uncertainty_mm per axis (0 when the mesh carries none);
// they are propagated to first order. Discretisation (linear interpolation
// between vertices) adds the quadric-versus-plane estimate of
// SurfaceQuery::InterpolationError in quadrature. A fitted plane adds its
// least-squares covariance (scaled by the residual variance).
//
// Errors: MeasurementError naming the input and reason.
#ifndef BSLS_MEASUREMENT_MEASURES_H_
#define BSLS_MEASUREMENT_MEASURES_H_

#include <Eigen/Core>
#include <vector>

#include "bsls/measurement/surface_query.h"

namespace bsls::measurement {

// A measured figure and its 1-sigma uncertainty, in the same unit.
struct Measured {
  double value = 0.0;
  double uncertainty = 0.0;
};

// A plane z = c0 + c1 (x - x0) + c2 (y - y0) fitted to surface vertices.
struct ReferencePlane {
  Eigen::Vector2d origin = Eigen::Vector2d::Zero();  // (x0, y0), mm
  Eigen::Vector3d coefficients = Eigen::Vector3d::Zero();
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();  // of the coefficients
  double residual_rms_mm = 0.0;                          // vertical residuals
  int vertices = 0;                                      // used in the fit

  // Unit normal, +z side.
  Eigen::Vector3d Normal() const;
  // Plane height z at (x, y) (mm).
  double Z(const Eigen::Vector2d& xy) const;
  // 1-sigma uncertainty of Z at (x, y) from the fit covariance (mm).
  double SigmaZ(const Eigen::Vector2d& xy) const;
};

// Least-squares plane through the vertices whose (x, y) lies inside
// `region`. Throws MeasurementError when fewer than 3 vertices lie in it.
ReferencePlane FitReferencePlane(const SurfaceQuery& surface, const Polygon2d& region);

// Height above the base plane z = 0 of the surface point over `xy`: its z
// (thesis eq. 2.1). Throws when `xy` is outside the surface.
Measured HeightAboveBase(const SurfaceQuery& surface, const Eigen::Vector2d& xy);

// Distance of the surface point over `xy` from `plane`, along the plane's
// normal, positive on its +z side.
Measured HeightAbovePlane(const SurfaceQuery& surface, const Eigen::Vector2d& xy,
                          const ReferencePlane& plane);

// Straight (3-D Euclidean) distance between the surface points over `a_xy`
// and `b_xy` (thesis eq. 7.1).
Measured StraightDistance(const SurfaceQuery& surface, const Eigen::Vector2d& a_xy,
                          const Eigen::Vector2d& b_xy);

// Area (mm^2) of the part of the surface whose (x, y) lies inside `region`:
// every face clipped by the polygon in x-y, its piece lifted onto the face's
// plane. Throws when the region holds no surface. Noise inflates it: a rough
// surface is larger than the smooth one it samples (docs/measurement.md).
Measured SurfaceArea(const SurfaceQuery& surface, const Polygon2d& region);

// Area (mm^2) of the given faces of `mesh`. Throws for an invalid index or an
// empty list.
Measured FacesArea(const geometry::SurfaceMesh& mesh, const std::vector<int>& faces);

}  // namespace bsls::measurement

#endif  // BSLS_MEASUREMENT_MEASURES_H_
