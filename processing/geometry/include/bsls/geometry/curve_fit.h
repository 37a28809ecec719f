// Least-squares curves through samples: a line or a parabola x(t) fitted
// to (t, x) pairs, t the free coordinate and x the fitted one (a stripe's
// centre as a function of the row, a segment's row as a function of the
// column, ...).
//
// Thread-safety: pure functions of their arguments.
#ifndef BSLS_GEOMETRY_CURVE_FIT_H_
#define BSLS_GEOMETRY_CURVE_FIT_H_

#include <array>
#include <optional>
#include <span>
#include <utility>
#include <vector>

namespace bsls::geometry {

using Sample = std::pair<double, double>;  // (t, x)
using Samples = std::vector<Sample>;
using Quadratic = std::array<double, 3>;  // x = c[0] + c[1] t + c[2] t^2

// Least-squares line x = a + b t through the samples; false with fewer than
// two or all at one t.
bool FitLine(std::span<const Sample> s, double* a, double* b);

// Least-squares x = c0 + c1 t + c2 t^2 through the samples; false when
// there are fewer than five or they do not fix a parabola.
bool FitParabola(std::span<const Sample> s, Quadratic* c);

// The value at t = 0 of a parabola through the samples (a line when there
// are fewer than five), or nullopt.
std::optional<double> FitAtZero(std::span<const Sample> s);

}  // namespace bsls::geometry

#endif  // BSLS_GEOMETRY_CURVE_FIT_H_
