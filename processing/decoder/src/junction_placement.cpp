#include "junction_placement.h"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <cstdint>
#include <span>

#include "bsls/geometry/curve_fit.h"

namespace bsls::decoder::internal {
namespace {

using geometry::FitLine;
using geometry::FitParabola;
using geometry::Quadratic;

// Drops from `columns` ((x, y) pairs) the one furthest from the line fitted
// through the others when it lies more than `max_residual` from it; true
// when one was dropped.
bool DropWorstColumn(std::vector<std::pair<double, double>>& columns, double max_residual) {
  double c, e;
  if (!FitLine(columns, &c, &e)) return false;
  const auto residual = [&](const std::pair<double, double>& p) {
    return std::abs(p.second - c - e * p.first);
  };
  const auto worst =
      std::max_element(columns.begin(), columns.end(),
                       [&](const auto& l, const auto& r) { return residual(l) < residual(r); });
  // The others in their order, then the worst: fitted without a copy.
  std::rotate(worst, worst + 1, columns.end());
  const std::span<const std::pair<double, double>> others(columns.data(), columns.size() - 1);
  if (!FitLine(others, &c, &e) || residual(columns.back()) <= max_residual) {
    std::rotate(worst, columns.end() - 1, columns.end());  // back in its place
    return false;
  }
  columns.pop_back();
  return true;
}

// Drops the columns far off the line through the others, the worst first,
// while four remain, and at most a third of them (one of four or five).
void DropOutlyingColumns(std::vector<std::pair<double, double>>& columns, double max_residual) {
  const size_t most = std::max<size_t>(1, columns.size() / 3);
  for (size_t dropped = 0; dropped < most && columns.size() >= 4; ++dropped)
    if (!DropWorstColumn(columns, max_residual)) break;
}

}  // namespace

ColumnCentres ColumnCentres::Wanted(const std::vector<JunctionPlan>& plans) {
  // Sorted as one integer each (x, then y: the pairs' order, as the
  // columns lie in the frame, x and y >= 0).
  std::vector<std::uint64_t> packed;
  for (const JunctionPlan& plan : plans)
    for (const cv::Point& c : plan.columns) {
      assert(c.x >= 0 && c.y >= 0);
      packed.push_back(static_cast<std::uint64_t>(c.x) << 32 | static_cast<std::uint32_t>(c.y));
    }
  std::sort(packed.begin(), packed.end());
  packed.erase(std::unique(packed.begin(), packed.end()), packed.end());
  ColumnCentres out;
  out.keys.reserve(packed.size());
  for (std::uint64_t k : packed)
    out.keys.emplace_back(static_cast<int>(k >> 32), static_cast<int>(k & 0xffffffffu));
  out.centres.resize(out.keys.size());
  return out;
}

void ColumnCentres::Fill(JunctionPlan* plan) const {
  plan->centres.clear();
  plan->centres.reserve(plan->columns.size());
  for (const cv::Point& s : plan->columns) plan->centres.push_back(At(s));
}

bool FitMeasuredSegment(const JunctionPlan& plan, const DecodeParams& params, double* c,
                        double* e) {
  assert(plan.centres.size() == plan.columns.size());
  // (x - a, y); one buffer per thread, as this runs once or twice per junction.
  thread_local std::vector<std::pair<double, double>> measured;
  measured.clear();
  for (size_t k = 0; k < plan.columns.size(); ++k)
    if (const std::optional<double>& cy = plan.centres[k])
      measured.push_back({plan.columns[k].x - plan.a, *cy});
  // A column far off the line through the others is dropped: where a line
  // leans towards the segment's side below or above the junction, its
  // light reaches into the column profiles nearest to it (one in a short
  // segment of 5 columns moved the chin's corner junctions 4 px, and
  // beside a steep line two of them do), and the far line's into the
  // last ones.
  DropOutlyingColumns(measured, 2.0 * params.max_centre_residual);
  return measured.size() >= 2 && FitLine(measured, c, e);
}

// The junction where the line's centre curve meets the segment's: the line's
// measured centres near the junction fitted as x(y), the segment's centres
// measured column by column along its skeleton (plan.columns, from `columns`)
// and fitted as y(x). An interpolated junction, or one whose segment cannot be
// measured, is placed on the line's fit at its row. nullopt when the line has
// too few centres near it.
std::optional<cv::Point2d> RefineJunction(const JunctionPlan& plan, double y0,
                                          const DecodeParams& params, int n) {
  if (!plan.ok) return std::nullopt;
  // How far from the skeleton's junction row the meeting point may lie.
  const double reach = params.junction_clearance + 1.0 * n;
  const double a = plan.a, b = plan.b;
  const std::vector<std::pair<double, double>>& vertical = plan.vertical;
  double y = y0;
  if (!plan.columns.empty()) {
    // The segment as y(x): centres column by column along its skeleton, or the
    // skeleton itself.
    double c, e;
    bool fitted = FitMeasuredSegment(plan, params, &c, &e);
    if (!fitted) {
      std::vector<std::pair<double, double>> skeleton;  // (x - a, y)
      for (const cv::Point& s : plan.columns) skeleton.push_back({s.x - a, 1.0 * s.y});
      fitted = skeleton.size() >= 2 && FitLine(skeleton, &c, &e);
    }
    if (fitted) {
      // Where x = a' + b' (y - y0) meets y = c + e (x - a):
      //   y = (c + e (a' - a) - e b' y0) / (1 - e b').
      auto meet = [&](double a2, double b2, double* out) {
        const double den = 1.0 - e * b2;
        if (std::abs(den) < 1e-6) return false;
        *out = (c + e * (a2 - a) - e * b2 * y0) / den;
        return std::abs(*out - y0) <= reach;
      };
      // Where the parabola x = k0 + k1 t + k2 t^2 (t = y - y0) meets the
      // segment: e k2 t^2 + (e k1 - 1) t + c + e (k0 - a) - y0 = 0; the root
      // nearer t = 0, in the form that stays exact as e k2 -> 0.
      auto meet_curve = [&](const Quadratic& k, cv::Point2d* out) {
        const double qa = e * k[2], qb = e * k[1] - 1.0, qc = c + e * (k[0] - a) - y0;
        const double disc = qb * qb - 4 * qa * qc;
        if (disc < 0) return false;
        const double t = 2 * qc / (-qb + std::copysign(std::sqrt(disc), -qb));
        if (std::abs(t) > reach) return false;
        *out = cv::Point2d(k[0] + k[1] * t + k[2] * t * t, y0 + t);
        return true;
      };
      std::vector<std::pair<double, double>> upper, lower;
      for (const auto& v : vertical) (v.first < 0 ? upper : lower).push_back(v);
      double au, bu, al, bl, yu, yl, ya;
      const bool branches = upper.size() >= 2 && lower.size() >= 2 && FitLine(upper, &au, &bu) &&
                            FitLine(lower, &al, &bl);
      // A line folding near its junction (nose, lips): the branches above and
      // below meet the segment each on its own. A segment coming from the
      // fold's open side runs into the branch at its row first: the meeting
      // point nearer its side (the other one lies on the far branch's
      // extension beyond the tip), where that branch, curving into the fold,
      // is fitted as a parabola over twice the rows when it has them. A
      // segment coming at the tip from outside, or branches meeting it within
      // fold_tip_spread of each other, meet the fold at its tip: the junction
      // lies between the meeting points.
      if (branches && std::abs(bu - bl) > params.fold_slope_change) {
        if (meet(au, bu, &yu) && meet(al, bl, &yl)) {
          const double xu = au + bu * (yu - y0), xl = al + bl * (yl - y0);
          double side = 0.0;  // > 0: the segment comes from the right
          for (const cv::Point& s : plan.columns) side += s.x - a;
          const bool tip_right = bu > bl;
          if ((side > 0) == tip_right || std::abs(xu - xl) <= params.fold_tip_spread)
            return cv::Point2d(0.5 * (xu + xl), 0.5 * (yu + yl));
          const bool entered_upper = (side > 0) == (xu > xl);
          std::vector<std::pair<double, double>> branch;
          for (const auto& v : plan.wide)
            if ((v.first < 0) == entered_upper) branch.push_back(v);
          cv::Point2d curved;
          if (Quadratic k; FitParabola(branch, &k) && meet_curve(k, &curved)) return curved;
          return entered_upper ? cv::Point2d(xu, yu) : cv::Point2d(xl, yl);
        }
      } else if (Quadratic k; branches && FitParabola(vertical, &k)) {
        // A line curving smoothly through it: its centres on both sides as a
        // parabola.
        if (cv::Point2d curved; meet_curve(k, &curved)) return curved;
      } else if (!branches && std::min(upper.size(), lower.size()) == 1) {
        // A line with a single measured row on one side within reach (where
        // the nose wing hides a few rows of it next to the junction): its
        // centres on the other side, over twice the rows, as a parabola: a
        // line bending into the junction runs past a straight fit's meeting
        // point, and the lone row is no guide to a fold.
        std::vector<std::pair<double, double>> one_side;
        for (const auto& v : plan.wide)
          if ((v.first < 0) == (upper.size() >= 2)) one_side.push_back(v);
        cv::Point2d curved;
        if (Quadratic q; FitParabola(one_side, &q) && meet_curve(q, &curved)) return curved;
      }
      if (meet(a, b, &ya)) y = ya;
    }
  }
  return cv::Point2d(a + b * (y - y0), y);
}

}  // namespace bsls::decoder::internal
