#include "bsls/joining/features.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <utility>

#include "bsls/joining/join_error.h"

namespace bsls::joining {
namespace {

// Fewer resampled profile points than this cannot hold a nose and a mouth.
constexpr int kMinProfileSamples = 8;
// Gaussian kernels are cut at this many sigmas.
constexpr double kKernelHalfWidthSigmas = 3.0;

// The curve resampled every `step` mm of y from its top down (x, z
// interpolated linearly between neighbours, across gaps too).
std::vector<Eigen::Vector3d> Resample(const std::vector<Eigen::Vector3d>& points, double step) {
  std::vector<Eigen::Vector3d> out;
  if (points.size() < 2) return out;
  const double top = points.front().y();
  const double bottom = points.back().y();
  std::size_t i = 0;
  for (double y = top; y >= bottom; y -= step) {
    while (i + 2 < points.size() && points[i + 1].y() > y) ++i;
    const Eigen::Vector3d& a = points[i];
    const Eigen::Vector3d& b = points[i + 1];
    const double dy = a.y() - b.y();
    const double s = dy > 0.0 ? std::clamp((a.y() - y) / dy, 0.0, 1.0) : 0.0;
    Eigen::Vector3d p = a + s * (b - a);
    p.y() = y;
    out.push_back(p);
  }
  return out;
}

// Gaussian smoothing of x and z along the samples (normalised at the ends).
std::vector<Eigen::Vector3d> Smooth(const std::vector<Eigen::Vector3d>& profile,
                                    double sigma_samples) {
  if (sigma_samples <= 0.0) return profile;
  const int half = static_cast<int>(std::ceil(kKernelHalfWidthSigmas * sigma_samples));
  std::vector<double> kernel(2 * half + 1);
  for (int k = -half; k <= half; ++k)
    kernel[k + half] = std::exp(-0.5 * (k * k) / (sigma_samples * sigma_samples));
  std::vector<Eigen::Vector3d> out(profile.size());
  const int n = static_cast<int>(profile.size());
  for (int i = 0; i < n; ++i) {
    double weight = 0.0, x = 0.0, z = 0.0;
    for (int k = std::max(-half, -i); k <= std::min(half, n - 1 - i); ++k) {
      weight += kernel[k + half];
      x += kernel[k + half] * profile[i + k].x();
      z += kernel[k + half] * profile[i + k].z();
    }
    out[i] = {x / weight, profile[i].y(), z / weight};
  }
  return out;
}

// Thesis 5.2.2 (eq. 5.33): where the sign of the gradient of `values`
// changes, with a hysteresis of `min_turn`: an extreme is a turning point once
// the values have turned back from it by min_turn, and they rose (or fell)
// into it by as much. Alternates maxima and minima; the ends are not turning
// points. Returns (index, is a maximum) pairs.
std::vector<std::pair<std::size_t, bool>> TurningPoints(const std::vector<double>& values,
                                                        double min_turn) {
  std::vector<std::pair<std::size_t, bool>> out;
  enum class Trend { kUnknown, kRising, kFalling } trend = Trend::kUnknown;
  std::size_t high = 0, low = 0;  // extremes since the last turning point
  for (std::size_t i = 1; i < values.size(); ++i) {
    const double z = values[i];
    if (z > values[high]) high = i;
    if (z < values[low]) low = i;
    switch (trend) {
      case Trend::kUnknown:
        if (z - values[low] >= min_turn) {
          if (values.front() - values[low] >= min_turn) out.emplace_back(low, false);
          trend = Trend::kRising;
          high = i;
        } else if (values[high] - z >= min_turn) {
          if (values[high] - values.front() >= min_turn) out.emplace_back(high, true);
          trend = Trend::kFalling;
          low = i;
        }
        break;
      case Trend::kRising:
        if (values[high] - z >= min_turn) {
          out.emplace_back(high, true);
          trend = Trend::kFalling;
          low = i;
        }
        break;
      case Trend::kFalling:
        if (z - values[low] >= min_turn) {
          out.emplace_back(low, false);
          trend = Trend::kRising;
          high = i;
        }
        break;
    }
  }
  return out;
}

// "12.5 mm".
std::string Millimetres(double value) {
  char text[32];
  std::snprintf(text, sizeof text, "%.1f mm", value);
  return text;
}

}  // namespace

bool FeatureParams::IsValid(std::string* error) const {
  auto fail = [&](const char* why) {
    if (error) *error = why;
    return false;
  };
  if (!(resample_step_mm > 0.0)) return fail("resample_step_mm must be > 0");
  if (!(smoothing_mm >= 0.0)) return fail("smoothing_mm must be >= 0");
  if (!(min_turn_mm > 0.0)) return fail("min_turn_mm must be > 0");
  if (!(min_nose_to_mouth_mm > 0.0)) return fail("min_nose_to_mouth_mm must be > 0");
  if (!(max_nose_to_mouth_mm > min_nose_to_mouth_mm))
    return fail("max_nose_to_mouth_mm must be > min_nose_to_mouth_mm");
  return true;
}

std::vector<Eigen::Vector3d> LineFeatures::ControlPoints() const {
  return {turning_points[nose].position, turning_points[upper_lip].position,
          turning_points[mouth].position, turning_points[lower_lip].position};
}

LineFeatures FindLineFeatures(const StripeCurve& curve, const FeatureParams& params,
                              const std::string& side) {
  const std::vector<Eigen::Vector3d> profile =
      Smooth(Resample(curve.points(), params.resample_step_mm),
             params.smoothing_mm / params.resample_step_mm);
  if (static_cast<int>(profile.size()) < kMinProfileSamples) {
    throw JoinError(JoinError::Reason::kFeaturesNotFound,
                    side + " mesh: the reference line is too short for nose and mouth (" +
                        std::to_string(curve.size()) + " vertices)");
  }
  LineFeatures features;
  std::vector<double> heights(profile.size());
  for (std::size_t i = 0; i < profile.size(); ++i) heights[i] = profile[i].z();
  std::vector<std::size_t> index;  // profile sample of each turning point
  for (const auto& [i, maximum] : TurningPoints(heights, params.min_turn_mm)) {
    features.turning_points.push_back({profile[i], maximum});
    index.push_back(i);
  }
  const std::vector<TurningPoint> tp = features.turning_points;
  const int count = static_cast<int>(tp.size());
  // Thesis 5.2.2, nose rules 1-2: the largest peak, not the lowest turning point.
  for (int k = 0; k + 1 < count; ++k) {
    if (tp[k].maximum && (features.nose < 0 || tp[k].position.z() > tp[features.nose].position.z()))
      features.nose = k;
  }
  if (features.nose < 0) {
    throw JoinError(JoinError::Reason::kFeaturesNotFound,
                    side + " mesh: no nose on the reference line (" + std::to_string(count) +
                        " turning points, none a peak above another turning point)");
  }
  // Thesis 5.2.2, mouth rules 1-2: max, min, max below the nose, not sharing
  // it. First the rule as written; then, for a top lip that is no turning
  // point of z (the philtrum slopes back: the lip only stands out from the
  // line joining nose and mouth), the valley right after the nose with the
  // top lip found on the profile taken relative to that line.
  const double nose_y = tp[features.nose].position.y();
  auto in_range = [&](int k) {
    const double drop = nose_y - tp[k].position.y();
    return drop >= params.min_nose_to_mouth_mm && drop <= params.max_nose_to_mouth_mm;
  };
  for (int k = features.nose + 1; k + 2 < count && features.mouth < 0; ++k) {
    if (tp[k].maximum && !tp[k + 1].maximum && tp[k + 2].maximum && in_range(k + 1)) {
      features.upper_lip = k;
      features.mouth = k + 1;
      features.lower_lip = k + 2;
    }
  }
  const int valley = features.nose + 1;
  if (features.mouth < 0 && valley + 1 < count && in_range(valley)) {
    // The profile between nose and mouth seen along the line joining them:
    // its turning points are the nose's underside (max), the foot of the nose
    // (min) and the top lip (max); the top lip is the last maximum after a minimum.
    const std::size_t from = index[features.nose], to = index[valley];
    const Eigen::Vector3d& top = profile[from];
    const Eigen::Vector3d& bottom = profile[to];
    std::vector<double> above_chord;
    for (std::size_t i = from; i <= to; ++i) {
      const double s = (top.y() - profile[i].y()) / (top.y() - bottom.y());
      above_chord.push_back(profile[i].z() - (top.z() + s * (bottom.z() - top.z())));
    }
    int top_lip = -1;
    bool after_minimum = false;
    for (const auto& [i, maximum] : TurningPoints(above_chord, params.min_turn_mm)) {
      if (!maximum) after_minimum = true;
      if (maximum && after_minimum) top_lip = static_cast<int>(from + i);
    }
    if (top_lip >= 0) {
      features.turning_points.insert(features.turning_points.begin() + valley,
                                     TurningPoint{profile[top_lip], true});
      features.upper_lip = valley;
      features.mouth = valley + 1;
      features.lower_lip = valley + 2;
    }
  }
  if (features.mouth < 0) {
    throw JoinError(JoinError::Reason::kFeaturesNotFound,
                    side + " mesh: no mouth (peak, valley, peak) " +
                        Millimetres(params.min_nose_to_mouth_mm) + " to " +
                        Millimetres(params.max_nose_to_mouth_mm) +
                        " below the nose on the reference line");
  }
  return features;
}

}  // namespace bsls::joining
