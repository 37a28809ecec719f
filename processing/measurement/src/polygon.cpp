#include "polygon.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace bsls::measurement::internal {

double SignedArea(const Polygon2d& polygon) {
  double twice = 0.0;
  for (std::size_t i = 0, n = polygon.size(); i < n; ++i) {
    const Eigen::Vector2d& a = polygon[i];
    const Eigen::Vector2d& b = polygon[(i + 1) % n];
    twice += a.x() * b.y() - b.x() * a.y();
  }
  return 0.5 * twice;
}

Eigen::Vector2d Centroid(const Polygon2d& polygon) {
  Eigen::Vector2d sum = Eigen::Vector2d::Zero();
  double twice = 0.0;
  for (std::size_t i = 0, n = polygon.size(); i < n; ++i) {
    const Eigen::Vector2d& a = polygon[i];
    const Eigen::Vector2d& b = polygon[(i + 1) % n];
    const double cross = a.x() * b.y() - b.x() * a.y();
    twice += cross;
    sum += (a + b) * cross;
  }
  if (std::abs(twice) < 1e-15) {
    Eigen::Vector2d mean = Eigen::Vector2d::Zero();
    for (const auto& p : polygon) mean += p;
    return polygon.empty() ? mean : Eigen::Vector2d(mean / polygon.size());
  }
  return sum / (3.0 * twice);
}

bool Contains(const Polygon2d& polygon, const Eigen::Vector2d& point) {
  bool inside = false;
  for (std::size_t i = 0, n = polygon.size(), j = n - 1; i < n; j = i++) {
    const Eigen::Vector2d& a = polygon[i];
    const Eigen::Vector2d& b = polygon[j];
    if ((a.y() > point.y()) != (b.y() > point.y()) &&
        point.x() < (b.x() - a.x()) * (point.y() - a.y()) / (b.y() - a.y()) + a.x())
      inside = !inside;
  }
  return inside;
}

double DistanceToBoundary(const Polygon2d& polygon, const Eigen::Vector2d& point) {
  double best = std::numeric_limits<double>::infinity();
  for (std::size_t i = 0, n = polygon.size(); i < n; ++i) {
    const Eigen::Vector2d& a = polygon[i];
    const Eigen::Vector2d ab = polygon[(i + 1) % n] - a;
    const double t =
        ab.squaredNorm() > 0.0 ? std::clamp((point - a).dot(ab) / ab.squaredNorm(), 0.0, 1.0) : 0.0;
    best = std::min(best, (a + t * ab - point).norm());
  }
  return best;
}

Polygon2d ClipByConvex(const Polygon2d& subject, const Polygon2d& clip) {
  Polygon2d output = subject;
  for (std::size_t i = 0, n = clip.size(); i < n && !output.empty(); ++i) {
    const Eigen::Vector2d& a = clip[i];
    const Eigen::Vector2d edge = clip[(i + 1) % n] - a;
    // Inside: left of the edge (counter-clockwise clip polygon).
    auto side = [&](const Eigen::Vector2d& p) {
      const Eigen::Vector2d d = p - a;
      return edge.x() * d.y() - edge.y() * d.x();
    };
    Polygon2d input;
    input.swap(output);
    for (std::size_t k = 0, m = input.size(); k < m; ++k) {
      const Eigen::Vector2d& p = input[k];
      const Eigen::Vector2d& q = input[(k + 1) % m];
      const double sp = side(p), sq = side(q);
      if (sp >= 0.0) output.push_back(p);
      if ((sp >= 0.0) != (sq >= 0.0)) output.push_back(p + (q - p) * (sp / (sp - sq)));
    }
  }
  return output;
}

Polygon2d ClipByLevel(const Polygon2d& polygon, const std::vector<double>& values, double level) {
  Polygon2d output;
  for (std::size_t k = 0, m = polygon.size(); k < m; ++k) {
    const double vp = values[k] - level, vq = values[(k + 1) % m] - level;
    const Eigen::Vector2d& p = polygon[k];
    const Eigen::Vector2d& q = polygon[(k + 1) % m];
    if (vp >= 0.0) output.push_back(p);
    if ((vp >= 0.0) != (vq >= 0.0)) output.push_back(p + (q - p) * (vp / (vp - vq)));
  }
  return output;
}

Eigen::AlignedBox2d Bounds(const Polygon2d& polygon) {
  Eigen::AlignedBox2d box;
  for (const auto& p : polygon) box.extend(p);
  return box;
}

Eigen::AlignedBox2d Grown(Eigen::AlignedBox2d box, double margin_mm) {
  const Eigen::Vector2d margin = Eigen::Vector2d::Constant(margin_mm);
  box.extend(box.min() - margin);
  box.extend(box.max() + margin);
  return box;
}

void CheckPolygon(const Polygon2d& polygon, const std::string& what) {
  if (polygon.size() < 3)
    throw MeasurementError(what + ": a polygon needs at least 3 vertices, got " +
                           std::to_string(polygon.size()));
  for (const auto& p : polygon)
    if (!p.allFinite()) throw MeasurementError(what + ": polygon vertex is not finite");
  if (std::abs(SignedArea(polygon)) < 1e-12)
    throw MeasurementError(what + ": polygon has zero area");
}

Eigen::Vector3d Barycentric(const Eigen::Vector2d& a, const Eigen::Vector2d& b,
                            const Eigen::Vector2d& c, const Eigen::Vector2d& p) {
  const Eigen::Vector2d v0 = b - a, v1 = c - a, v2 = p - a;
  const double det = v0.x() * v1.y() - v1.x() * v0.y();
  if (std::abs(det) < 1e-300) return {1.0, 0.0, 0.0};
  const double u = (v2.x() * v1.y() - v1.x() * v2.y()) / det;
  const double v = (v0.x() * v2.y() - v2.x() * v0.y()) / det;
  return {1.0 - u - v, u, v};
}

}  // namespace bsls::measurement::internal
