// Lumps and cavities measured against a smooth reference surface (thesis 7.2,
// Tables 7.3 and 7.4: maximum height or depth from the facial surface, and
// area; here also the volume).
//
// Method (docs/measurement.md):
//  1. Reference: a surface z = f(x, y) fitted by robust (Huber, IRLS) least
//     squares to the vertices of the ring around the region: those outside
//     the region polygon within ring_width_mm of its boundary. A plane cannot
//     follow a cheek (a 100 mm radius cheek sags 4.5 mm over 30 mm); on the
//     simulated face a quadric leaves 0.4-1 mm RMS on 14 mm rings, a cubic
//     (default) 0.12-0.5 mm, and the ring surrounds the region so the cubic
//     interpolates, not extrapolates. The thesis, too, measures against the
//     smooth facial surface the lesion interrupts.
//  2. Deviation of each vertex: d = z - f(x, y), vertical (the thesis measures
//     heights along z, eq. 2.1), linear over each face.
//  3. Peak: the vertex of largest |d| in the region gives the sign (lump or
//     cavity) and a window of peak_fit_radius_mm around it; a quadratic
//     fitted to d in the window gives the peak as its extremum (averages the
//     noise that biases a plain maximum upwards). When the window holds a
//     single stripe (stripes 5.7 mm apart, default window 4 mm) the fit is
//     1-D along it: no extrapolation between stripes, so a peak narrower
//     than the stripe spacing is underestimated (thesis Tables 7.3-7.4).
//  4. Area: of the part of the region where |d| >= level_fraction * |peak|
//     (default 0.5: the area at half height), cut from the faces at the
//     interpolated level (on an edge across stripes, where the mesh labels
//     its stripes, from the cubic through four stripes; linearly along a
//     stripe), measured on the reference surface (the footprint the lesion
//     covers on the face; noise does not inflate it).
//     Half height is where a smooth profile is steepest and inflects, so the
//     level line moves least with reference and noise errors and linear
//     interpolation between stripes is exact to second order there.
//  5. Volume: integral of d over the region (signed: > 0 for a lump).
//  6. Holes filled: the area and volume again with every hole in the region
//     (no surface, or no reference under it) filled by a thin plate through
//     the deviation around it, taken as 0 outside the region where nothing
//     was measured (the face undisturbed there: the premise of the region
//     and its reference) (hole_fill.h); flagged with the share interpolated.
//
// Against a baseline (MeasureLesionAgainstBaseline): the reference is an
// earlier scan of the same face without the lesion (before it grew, before
// surgery), rigidly registered onto the surface outside the region
// (baseline_registration.h); steps 2-5 are the same with f the baseline's
// height. No guess of the face under the lesion is needed, so the face's own
// shape no longer limits the figures, only both scans' noise does.
//
// Frame and units: world mm, mm^2, mm^3. Errors: MeasurementError naming the
// input and reason (region without surface, too few ring vertices, ...).
#ifndef BSLS_MEASUREMENT_LESION_MEASURE_H_
#define BSLS_MEASUREMENT_LESION_MEASURE_H_

#include <Eigen/Core>
#include <optional>
#include <string>

#include "bsls/geometry/surface_mesh.h"
#include "bsls/measurement/baseline_registration.h"
#include "bsls/measurement/measures.h"
#include "bsls/measurement/surface_query.h"

namespace bsls::measurement {

// Fitted ring references, or an earlier scan (MeasureLesionAgainstBaseline only).
enum class ReferenceKind { kPlane, kQuadric, kCubic, kBaseline };

// Returns "plane", "quadric", "cubic" or "baseline".
std::string ToString(ReferenceKind kind);

struct LesionMeasureParams {
  double ring_width_mm = 10.0;  // width of the ring the reference is fitted to, > 0
  ReferenceKind reference = ReferenceKind::kCubic;
  double level_fraction = 0.5;      // area level as a fraction of |peak|, in (0, 1)
  double peak_fit_radius_mm = 4.0;  // window of the peak's quadratic fit, > 0
  double huber_k = 2.0;             // Huber threshold in robust sigmas (MAD), > 0
  int robust_iterations = 8;        // IRLS rounds of the reference fit, >= 1

  // True when the numbers are in range; otherwise names the field and why.
  bool IsValid(std::string* error) const;
};

// z = f(x - x0, y - y0): plane c0 + c1 x + c2 y, quadric adds c3 x^2 + c4 xy + c5 y^2,
// cubic adds c6 x^3 + c7 x^2 y + c8 x y^2 + c9 y^3. Of a baseline only the
// description is kept (kind, origin, ring residual and count; no coefficients).
struct ReferenceSurface {
  ReferenceKind kind = ReferenceKind::kQuadric;
  Eigen::Vector2d origin = Eigen::Vector2d::Zero();  // (x0, y0), mm: the region's centroid
  Eigen::VectorXd coefficients;                      // 3 (plane), 6 (quadric), 10 (cubic)
  Eigen::MatrixXd covariance;                        // of the coefficients, mm^2 units
  double residual_rms_mm = 0.0;                      // robust RMS of the ring's vertical residuals
  int ring_vertices = 0;

  // Height z of the reference at (x, y), mm (fitted kinds only, as the two below).
  double Z(const Eigen::Vector2d& xy) const;
  // (dz/dx, dz/dy) at (x, y).
  Eigen::Vector2d Gradient(const Eigen::Vector2d& xy) const;
  // 1-sigma uncertainty of Z at (x, y) from the fit covariance, mm.
  double SigmaZ(const Eigen::Vector2d& xy) const;
};

struct LesionMeasurement {
  bool cavity = false;  // the largest deviation is below the reference
  // Height of a lump or depth of a cavity (mm, >= 0), along z from the reference.
  Measured peak_mm;
  Eigen::Vector3d peak_position = Eigen::Vector3d::Zero();  // on the lesion, world mm
  double level_mm = 0.0;     // the |d| level of the area (level_fraction * peak)
  Measured area_mm2;         // where |d| >= level_mm, on the reference surface
  Measured volume_mm3;       // of |d| over the region (cavity: volume missing), >= 0 normally
  Measured region_area_mm2;  // the whole region, on the measured surface
  // Share of the region's x-y area the measured surface covers, (0, 1]: below
  // 1 where stripes were lost or hidden (shadow, occlusion), and the area and
  // volume miss what lies in those holes.
  double surface_coverage = 1.0;
  // The area and volume with the region's holes (no surface, or no
  // reference under it) filled by interpolation: the deviation carried into
  // each hole from the surface around it and from d = 0 outside the region
  // (thin plate, least squared Laplacian). An estimate, not a measurement:
  // `filled_share` is the share of the region's x-y area that was
  // interpolated, and the uncertainties add the spread between the thin
  // plate and a membrane fill. Equal to area_mm2 and volume_mm3 when the
  // surface covers the region.
  Measured filled_area_mm2;
  Measured filled_volume_mm3;
  double filled_share = 0.0;
  ReferenceSurface reference;
  int region_vertices = 0;
  // Against a baseline: how it was registered onto this surface.
  std::optional<BaselineRegistration> baseline;
};

// Fits the reference of `params` to the ring around `region`. Throws when the
// ring holds too few vertices (6 for a quadric, 3 for a plane) or they are
// degenerate.
ReferenceSurface FitReference(const SurfaceQuery& surface, const Polygon2d& region,
                              const LesionMeasureParams& params);

// Measures the lump or cavity inside `region` (see the method above). Throws
// when the region holds no surface or the reference cannot be fitted.
LesionMeasurement MeasureLesion(const SurfaceQuery& surface, const Polygon2d& region,
                                const LesionMeasureParams& params = {});

// Measures the lump or cavity inside `region` against `baseline`, an earlier
// scan of the same face registered onto `surface` outside the region (the
// figures are in `surface`'s frame; params.reference is not used). Throws
// MeasurementError when the baseline has no faces, the registration fails,
// or the baseline lies under less than baseline_params.min_coverage of the
// region.
LesionMeasurement MeasureLesionAgainstBaseline(const SurfaceQuery& surface,
                                               const geometry::SurfaceMesh& baseline,
                                               const Polygon2d& region,
                                               const LesionMeasureParams& params = {},
                                               const BaselineParams& baseline_params = {});

}  // namespace bsls::measurement

#endif  // BSLS_MEASUREMENT_LESION_MEASURE_H_
