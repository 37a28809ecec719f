// Uniform cubic B-spline interpolation of scalar samples (thesis Appendix B,
// eq. B.4-B.11): the curve passes through knots P_0..P_N given at the
// parameter values tau = 0..N, with clamped end gradients.
//
// Units: tau in knot intervals; values and gradients in the caller's units
// (gradients per knot interval).
//
// Thread-safety: a value type.
#ifndef BSLS_RECONSTRUCTION_BSPLINE_H_
#define BSLS_RECONSTRUCTION_BSPLINE_H_

#include <optional>
#include <vector>

namespace bsls::reconstruction {

class CubicBSpline {
 public:
  // Thesis eq. B.7 for every knot plus the clamped end conditions B.10-B.11
  // (dP/dtau = start_gradient at tau = 0 and end_gradient at tau = N), solved
  // for the N + 3 control points A_-1..A_N+1. nullopt for fewer than 2 knots
  // or a non-finite input.
  static std::optional<CubicBSpline> Interpolate(const std::vector<double>& knots,
                                                 double start_gradient, double end_gradient);
  // The same with the end gradients estimated by one-sided differences of the
  // first and last two knots (reproduces straight lines exactly).
  static std::optional<CubicBSpline> Interpolate(const std::vector<double>& knots);

  // Thesis eq. B.6: the curve at tau, clamped to [0, N].
  double operator()(double tau) const;
  // Number of knot intervals N.
  int intervals() const { return static_cast<int>(control_.size()) - 3; }

 private:
  explicit CubicBSpline(std::vector<double> control) : control_(std::move(control)) {}
  std::vector<double> control_;  // A_-1 .. A_N+1
};

// Thesis eq. B.4: the cubic B-spline blending function B(x), support (-2, 2).
double CubicBSplineBlend(double x);

}  // namespace bsls::reconstruction

#endif  // BSLS_RECONSTRUCTION_BSPLINE_H_
