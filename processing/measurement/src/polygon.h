// Planar polygon helpers of the measurement stage (x-y plane, mm).
#ifndef BSLS_MEASUREMENT_SRC_POLYGON_H_
#define BSLS_MEASUREMENT_SRC_POLYGON_H_

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <string>
#include <vector>

#include "bsls/measurement/surface_query.h"

namespace bsls::measurement::internal {

// Signed area (counter-clockwise positive), shoelace formula.
double SignedArea(const Polygon2d& polygon);
// Area centroid; the vertex mean for a degenerate polygon.
Eigen::Vector2d Centroid(const Polygon2d& polygon);
// True when `point` lies inside (even-odd rule).
bool Contains(const Polygon2d& polygon, const Eigen::Vector2d& point);
// Distance from `point` to the polygon's boundary.
double DistanceToBoundary(const Polygon2d& polygon, const Eigen::Vector2d& point);
// `subject` clipped by the convex counter-clockwise `clip` (Sutherland-Hodgman;
// exact in area for any simple subject).
Polygon2d ClipByConvex(const Polygon2d& subject, const Polygon2d& clip);
// The part of convex `polygon` where the affine function with values
// `values` at its vertices is >= level (the values are clipped alongside).
Polygon2d ClipByLevel(const Polygon2d& polygon, const std::vector<double>& values, double level);
// Bounding box.
Eigen::AlignedBox2d Bounds(const Polygon2d& polygon);
// `box` grown by `margin_mm` on every side.
Eigen::AlignedBox2d Grown(Eigen::AlignedBox2d box, double margin_mm);
// Throws MeasurementError "<what>: ..." unless the polygon has >= 3 finite
// vertices and a non-zero area.
void CheckPolygon(const Polygon2d& polygon, const std::string& what);
// Barycentric weights of `p` in triangle (a, b, c) (x-y); zero-area: (1,0,0).
Eigen::Vector3d Barycentric(const Eigen::Vector2d& a, const Eigen::Vector2d& b,
                            const Eigen::Vector2d& c, const Eigen::Vector2d& p);

}  // namespace bsls::measurement::internal

#endif  // BSLS_MEASUREMENT_SRC_POLYGON_H_
