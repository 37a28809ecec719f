#include "bsls/geometry/curve_fit.h"

#include <cmath>
#include <limits>

namespace bsls::geometry {

// Least-squares line x = a + b t through (t, x) samples; false with < 2 samples.
bool FitLine(std::span<const Sample> s, double* a, double* b) {
  if (s.size() < 2) return false;
  double st = 0, sx = 0, stt = 0, stx = 0;
  for (const auto& [t, x] : s) {
    st += t;
    sx += x;
    stt += t * t;
    stx += t * x;
  }
  const double n = static_cast<double>(s.size());
  const double den = n * stt - st * st;
  if (std::abs(den) < 1e-9) return false;
  *b = (n * stx - st * sx) / den;
  *a = (sx - *b * st) / n;
  return true;
}

// Least-squares x = c0 + c1 t + c2 t^2 through (t, x) samples; false when
// there are fewer than five or they do not fix a parabola. The normal
// equations are solved by Cholesky's method (as cv::solve's DECOMP_CHOLESKY),
// written out for 3 x 3.
bool FitParabola(std::span<const Sample> s, Quadratic* c) {
  if (s.size() < 5) return false;
  double m[5] = {0, 0, 0, 0, 0};  // sums of t^0 .. t^4
  double r[3] = {0, 0, 0};        // sums of x, t x, t^2 x
  for (const auto& [t, x] : s) {
    const double t2 = t * t;
    m[0] += 1.0;
    m[1] += t;
    m[2] += t2;
    m[3] += t * t2;
    m[4] += t2 * t2;
    r[0] += x;
    r[1] += t * x;
    r[2] += t2 * x;
  }
  constexpr double kMin = std::numeric_limits<double>::epsilon();
  // A = L L^T with A = [m0 m1 m2; m1 m2 m3; m2 m3 m4].
  double d0 = m[0];
  if (d0 < kMin) return false;
  const double l00 = std::sqrt(d0);
  const double l10 = m[1] / l00, l20 = m[2] / l00;
  const double d1 = m[2] - l10 * l10;
  if (d1 < kMin) return false;
  const double l11 = std::sqrt(d1);
  const double l21 = (m[3] - l20 * l10) / l11;
  const double d2 = m[4] - l20 * l20 - l21 * l21;
  if (d2 < kMin) return false;
  const double l22 = std::sqrt(d2);
  // L y = r, then L^T c = y.
  const double y0 = r[0] / l00;
  const double y1 = (r[1] - l10 * y0) / l11;
  const double y2 = (r[2] - l20 * y0 - l21 * y1) / l22;
  (*c)[2] = y2 / l22;
  (*c)[1] = (y1 - l21 * (*c)[2]) / l11;
  (*c)[0] = (y0 - l10 * (*c)[1] - l20 * (*c)[2]) / l00;
  return true;
}

// The value at t = 0 of a parabola through (t, x) samples (a line when there
// are fewer than five), or nullopt.
std::optional<double> FitAtZero(std::span<const Sample> s) {
  Quadratic c;
  if (FitParabola(s, &c)) return c[0];
  double a, b;
  if (!FitLine(s, &a, &b)) return std::nullopt;
  return a;
}

}  // namespace bsls::geometry
