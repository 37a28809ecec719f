// Heights between the stripes of a reconstructed mesh, interpolated across
// the stripes by a cubic instead of the mesh's flat triangles, for the
// lesion measurement (lesion_measure.cpp).
//
// A structured-light mesh is dense along each stripe (a sample per pixel)
// and sparse across them (5-6 mm between neighbouring lines on a face). Its
// triangles interpolate linearly across that gap, so a level cut through
// them sags towards the chords and depends on how the strips were split into
// triangles (row pairs or stitched fans). The field here depends only on the
// stripes: on the row through a point (a line across the stripes), the
// stripes' crossings are joined by a cubic Hermite whose slopes come from the
// parabola through each crossing and its neighbours (exact for a quadratic
// across the stripes; linear where a neighbouring stripe is missing).
//
// Frame and units: world x-y and z, millimetres (the mesh's).
// Ownership and thread-safety: copies what it needs; const members may be
// called concurrently.
#ifndef BSLS_MEASUREMENT_SRC_STRIPE_FIELD_H_
#define BSLS_MEASUREMENT_SRC_STRIPE_FIELD_H_

#include <Eigen/Core>
#include <optional>
#include <vector>

#include "bsls/geometry/surface_mesh.h"

namespace bsls::measurement::internal {

class StripeField {
 public:
  // Indexes the along-stripe edges (both ends on one labelled line) of the
  // faces `faces` of `mesh`; every Z() is nullopt when the mesh carries no
  // stripe labels.
  StripeField(const geometry::SurfaceMesh& mesh, const std::vector<int>& faces);

  // True when no along-stripe edge was found (Z() is always nullopt).
  bool empty() const { return segments_.empty(); }
  // z at `xy` from the cubic across the stripes on the row through it;
  // nullopt unless two neighbouring stripes (labels one apart) bracket it.
  std::optional<double> Z(const Eigen::Vector2d& xy) const;
  // Unit x-y direction the stripes run along (the rows run across it).
  const Eigen::Vector2d& along() const { return along_; }

 private:
  struct Segment {
    double s0, w0, z0, s1, w1, z1;  // ends in (across, along) coordinates
    int line;
  };

  Eigen::Vector2d along_ = Eigen::Vector2d::UnitY();
  Eigen::Vector2d across_ = Eigen::Vector2d::UnitX();
  double w_min_ = 0.0, bin_mm_ = 1.0;
  std::vector<Segment> segments_;
  std::vector<std::vector<int>> bins_;  // segments meeting each along-stripe bin
};

}  // namespace bsls::measurement::internal

#endif  // BSLS_MEASUREMENT_SRC_STRIPE_FIELD_H_
