// Private to bsls::decoder: least-squares curves through the sub-pixel
// centres of a line (x as a function of the row) or of a segment (y as a
// function of the column), which place junctions and refill skipped rows.
//
// Samples are (t, x) pairs: t the free coordinate, x the fitted one.
#ifndef BSLS_DECODER_SRC_CURVE_FIT_H_
#define BSLS_DECODER_SRC_CURVE_FIT_H_

#include <optional>
#include <span>
#include <utility>
#include <vector>

#include <opencv2/core.hpp>

namespace bsls::decoder::internal {

using Sample = std::pair<double, double>;
using Samples = std::vector<Sample>;

// Least-squares line x = a + b t through the samples; false with fewer than
// two or all at one t.
bool FitLine(std::span<const Sample> s, double* a, double* b);

// Least-squares x = c0 + c1 t + c2 t^2 through the samples; false when
// there are fewer than five or they do not fix a parabola.
bool FitParabola(std::span<const Sample> s, cv::Vec3d* c);

// The value at t = 0 of a parabola through the samples (a line when there
// are fewer than five), or nullopt.
std::optional<double> FitAtZero(std::span<const Sample> s);

}  // namespace bsls::decoder::internal

#endif  // BSLS_DECODER_SRC_CURVE_FIT_H_
