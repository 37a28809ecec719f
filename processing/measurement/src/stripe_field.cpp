#include "stripe_field.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <utility>

namespace bsls::measurement::internal {
namespace {

// Along-stripe bin height (mm): a few samples of each stripe per bin.
constexpr double kBinMm = 1.0;
// Bins at most: bounds the index of a mesh with a stray far vertex.
constexpr double kMaxBins = 200000.0;
// A neighbouring crossing steers the slope only when its gap is within
// this factor of the bracket's (a stripe that is not the next one across).
constexpr double kMaxGapRatio = 2.0;
// Crossings of one stripe closer than this (mm) are one (a shared vertex).
constexpr double kSameCrossingMm = 1e-9;

struct Crossing {
  double s, z;
  int line;
};

// Slope at the middle of three points: the parabola's through them.
double ParabolaSlope(const Crossing& a, const Crossing& b, const Crossing& c) {
  const double h0 = b.s - a.s, h1 = c.s - b.s;
  return ((b.z - a.z) / h0 * h1 + (c.z - b.z) / h1 * h0) / (h0 + h1);
}

}  // namespace

StripeField::StripeField(const geometry::SurfaceMesh& mesh, const std::vector<int>& faces) {
  if (mesh.line.size() != mesh.positions.size()) return;
  std::vector<std::pair<int, int>> edges;
  for (int f : faces)
    for (int k = 0; k < 3; ++k) {
      const int a = mesh.faces[f][k], b = mesh.faces[f][(k + 1) % 3];
      if (mesh.line[a] == mesh.line[b]) edges.emplace_back(std::min(a, b), std::max(a, b));
    }
  std::sort(edges.begin(), edges.end());
  edges.erase(std::unique(edges.begin(), edges.end()), edges.end());
  // The stripes' direction: the principal axis of their edges' directions.
  Eigen::Matrix2d scatter = Eigen::Matrix2d::Zero();
  for (const auto& [a, b] : edges) {
    const Eigen::Vector2d d = mesh.positions[b].head<2>() - mesh.positions[a].head<2>();
    if (d.norm() > 0.0) scatter += d.normalized() * d.normalized().transpose();
  }
  if (scatter.trace() <= 0.0) return;
  along_ = Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d>(scatter).eigenvectors().col(1);
  across_ = Eigen::Vector2d(along_.y(), -along_.x());
  double w_max = -std::numeric_limits<double>::infinity();
  w_min_ = std::numeric_limits<double>::infinity();
  for (const auto& [a, b] : edges) {
    const Eigen::Vector3d& p = mesh.positions[a];
    const Eigen::Vector3d& q = mesh.positions[b];
    Segment segment{p.head<2>().dot(across_),
                    p.head<2>().dot(along_),
                    p.z(),
                    q.head<2>().dot(across_),
                    q.head<2>().dot(along_),
                    q.z(),
                    mesh.line[a]};
    if (!std::isfinite(segment.s0 + segment.w0 + segment.z0 + segment.s1 + segment.w1 + segment.z1))
      continue;
    if (segment.w0 == segment.w1) continue;  // runs across: its ends lie on other edges
    if (segment.w0 > segment.w1) {
      std::swap(segment.s0, segment.s1);
      std::swap(segment.w0, segment.w1);
      std::swap(segment.z0, segment.z1);
    }
    w_min_ = std::min(w_min_, segment.w0);
    w_max = std::max(w_max, segment.w1);
    segments_.push_back(segment);
  }
  if (segments_.empty()) return;
  bin_mm_ = std::max(kBinMm, (w_max - w_min_) / kMaxBins);
  bins_.resize(static_cast<std::size_t>((w_max - w_min_) / bin_mm_) + 1);
  for (std::size_t i = 0; i < segments_.size(); ++i) {
    const auto first = static_cast<std::size_t>((segments_[i].w0 - w_min_) / bin_mm_);
    const auto last = static_cast<std::size_t>((segments_[i].w1 - w_min_) / bin_mm_);
    for (std::size_t bin = first; bin <= last && bin < bins_.size(); ++bin)
      bins_[bin].push_back(static_cast<int>(i));
  }
}

// Ours: the thesis joins neighbouring stripes by straight edges (5.2.1) and
// interpolates by cubics only along a stripe (App. B); this is a cubic
// across them.
std::optional<double> StripeField::Z(const Eigen::Vector2d& xy) const {
  if (segments_.empty()) return std::nullopt;
  const double s = xy.dot(across_), w = xy.dot(along_);
  const double bin = std::floor((w - w_min_) / bin_mm_);
  if (!(bin >= 0.0 && bin < static_cast<double>(bins_.size()))) return std::nullopt;
  std::vector<Crossing> crossings;
  for (int i : bins_[static_cast<std::size_t>(bin)]) {
    const Segment& g = segments_[i];
    if (w < g.w0 || w > g.w1) continue;
    const double t = (w - g.w0) / (g.w1 - g.w0);
    crossings.push_back({g.s0 + t * (g.s1 - g.s0), g.z0 + t * (g.z1 - g.z0), g.line});
  }
  std::sort(crossings.begin(), crossings.end(),
            [](const Crossing& a, const Crossing& b) { return a.s < b.s; });
  crossings.erase(std::unique(crossings.begin(), crossings.end(),
                              [](const Crossing& a, const Crossing& b) {
                                return a.line == b.line && b.s - a.s <= kSameCrossingMm;
                              }),
                  crossings.end());
  // The bracket: the last crossing at or before s and the next one.
  const auto right = std::upper_bound(crossings.begin(), crossings.end(), s,
                                      [](double value, const Crossing& c) { return value < c.s; });
  if (right == crossings.begin()) return std::nullopt;
  const std::size_t i = static_cast<std::size_t>(right - crossings.begin()) - 1;
  const Crossing& l = crossings[i];
  if (s - l.s <= kSameCrossingMm) return l.z;
  if (i + 1 >= crossings.size()) return std::nullopt;
  const Crossing& r = crossings[i + 1];
  const int step = r.line - l.line;
  const double h = r.s - l.s;
  if (std::abs(step) != 1 || !(h > 0.0)) return std::nullopt;
  const double secant = (r.z - l.z) / h;
  // The stripe beyond the bracket continues its labels' step; labels count
  // outwards from the reference line on both sides (contracts section 2),
  // so on a joined face the stripe beyond line 0 is labelled 1 again.
  auto neighbour = [&](std::size_t k, int line, double gap) {
    return crossings[k].line == line && gap > 0.0 && gap <= kMaxGapRatio * h &&
           h <= kMaxGapRatio * gap;
  };
  const double m_l = i > 0 && neighbour(i - 1, std::abs(l.line - step), l.s - crossings[i - 1].s)
                         ? ParabolaSlope(crossings[i - 1], l, r)
                         : secant;
  const double m_r = i + 2 < crossings.size() &&
                             neighbour(i + 2, std::abs(r.line + step), crossings[i + 2].s - r.s)
                         ? ParabolaSlope(l, r, crossings[i + 2])
                         : secant;
  // Cubic Hermite on [l, r].
  const double t = (s - l.s) / h, t2 = t * t, t3 = t2 * t;
  return (2.0 * t3 - 3.0 * t2 + 1.0) * l.z + (t3 - 2.0 * t2 + t) * h * m_l +
         (-2.0 * t3 + 3.0 * t2) * r.z + (t3 - t2) * h * m_r;
}

}  // namespace bsls::measurement::internal
