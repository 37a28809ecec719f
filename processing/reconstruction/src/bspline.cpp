#include "bsls/reconstruction/bspline.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <utility>

namespace bsls::reconstruction {

double CubicBSplineBlend(double x) {
  // Thesis eq. B.4, piecewise on [-2, -1], [-1, 0], [0, 1], [1, 2].
  const double a = std::abs(x);
  if (a >= 2.0) return 0.0;
  if (a >= 1.0) return (2.0 - a) * (2.0 - a) * (2.0 - a) / 6.0;
  return (4.0 - 6.0 * a * a + 3.0 * a * a * a) / 6.0;
}

std::optional<CubicBSpline> CubicBSpline::Interpolate(const std::vector<double>& knots,
                                                      double start_gradient, double end_gradient) {
  const int n = static_cast<int>(knots.size()) - 1;  // N
  if (n < 1) return std::nullopt;
  if (!std::isfinite(start_gradient) || !std::isfinite(end_gradient)) return std::nullopt;
  for (double k : knots)
    if (!std::isfinite(k)) return std::nullopt;
  // Unknowns A_-1..A_N+1 at columns 0..N+2. Rows: the start gradient (B.10),
  // P_j = (A_j-1 + 4 A_j + A_j+1) / 6 for j = 0..N (B.7), the end gradient (B.11).
  const int m = n + 3;
  Eigen::MatrixXd a = Eigen::MatrixXd::Zero(m, m);
  Eigen::VectorXd b(m);
  a(0, 0) = -0.5;
  a(0, 2) = 0.5;
  b[0] = start_gradient;
  for (int j = 0; j <= n; ++j) {
    a(j + 1, j) = 1.0 / 6.0;
    a(j + 1, j + 1) = 4.0 / 6.0;
    a(j + 1, j + 2) = 1.0 / 6.0;
    b[j + 1] = knots[j];
  }
  a(m - 1, m - 3) = -0.5;
  a(m - 1, m - 1) = 0.5;
  b[m - 1] = end_gradient;
  const Eigen::VectorXd control = a.partialPivLu().solve(b);
  if (!control.allFinite()) return std::nullopt;
  return CubicBSpline(std::vector<double>(control.data(), control.data() + m));
}

std::optional<CubicBSpline> CubicBSpline::Interpolate(const std::vector<double>& knots) {
  if (knots.size() < 2) return std::nullopt;
  const std::size_t n = knots.size() - 1;
  return Interpolate(knots, knots[1] - knots[0], knots[n] - knots[n - 1]);
}

double CubicBSpline::operator()(double tau) const {
  const int n = intervals();
  tau = std::clamp(tau, 0.0, static_cast<double>(n));
  // Thesis eq. B.6: sum over i = -1..N+1 of A_i B(tau - i); only the four
  // nearest control points contribute.
  const int centre = static_cast<int>(std::floor(tau));
  double value = 0.0;
  for (int i = std::max(-1, centre - 2); i <= std::min(n + 1, centre + 2); ++i)
    value += control_[i + 1] * CubicBSplineBlend(tau - i);
  return value;
}

}  // namespace bsls::reconstruction
