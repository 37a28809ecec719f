#include "bsls/measurement/plan.h"

#include <cmath>
#include <sstream>
#include <stdexcept>

#include "bsls/measurement/geodesic.h"
#include "bsls/measurement/measurement_error.h"
#include "bsls/measurement/measures.h"

namespace bsls::measurement {
namespace {

std::string PointText(const Eigen::Vector2d& p) {
  std::ostringstream out;
  out << "(" << p.x() << ", " << p.y() << ")";
  return out.str();
}

nlohmann::json PolygonJson(const Polygon2d& polygon) {
  nlohmann::json points = nlohmann::json::array();
  for (const Eigen::Vector2d& p : polygon) points.push_back({p.x(), p.y()});
  return points;
}

// A point of the world plane a face can be measured at: finite and within a
// kilometre of the origin (anything further is a typing error, and would
// overflow the surface's cell grid).
constexpr const char* kNotOnThePlane = "not a finite point within 1 km of the origin";

bool Finite(const Eigen::Vector2d& p) {
  return std::isfinite(p.x()) && std::isfinite(p.y()) && std::abs(p.x()) <= 1e6 &&
         std::abs(p.y()) <= 1e6;
}

}  // namespace

bool MeasurementPlan::empty() const {
  return heights.empty() && distances.empty() && areas.empty() && lesions.empty();
}

bool MeasurementPlan::IsValid(std::string* error) const {
  auto fail = [error](const std::string& why) {
    if (error) *error = why;
    return false;
  };
  for (size_t i = 0; i < heights.size(); ++i)
    if (!Finite(heights[i])) return fail("height " + std::to_string(i + 1) + ": " + kNotOnThePlane);
  for (size_t i = 0; i < distances.size(); ++i)
    if (!Finite(distances[i][0]) || !Finite(distances[i][1]))
      return fail("distance " + std::to_string(i + 1) + ": " + kNotOnThePlane);
  for (const auto* regions : {&areas, &lesions}) {
    const char* kind = regions == &areas ? "area " : "lesion ";
    for (size_t i = 0; i < regions->size(); ++i) {
      const Polygon2d& region = (*regions)[i];
      if (region.size() < 3)
        return fail(kind + std::to_string(i + 1) + ": a region needs at least 3 points");
      for (const Eigen::Vector2d& p : region)
        if (!Finite(p)) return fail(kind + std::to_string(i + 1) + ": " + kNotOnThePlane);
    }
  }
  if (baseline && lesions.empty()) return fail("a baseline is the reference of lesions: give one");
  std::string why;
  if (!lesion.IsValid(&why)) return fail("lesion parameters: " + why);
  if (lesion.ring_width_mm > 1000.0) return fail("lesion parameters: a ring wider than 1 m");
  return true;
}

MeasurementOutcome MeasurePlan(const geometry::SurfaceMesh& mesh, const MeasurementPlan& plan,
                               const Cancellation& cancel) {
  std::string why;
  if (!plan.IsValid(&why)) throw std::invalid_argument("measurement plan: " + why);
  MeasurementOutcome out;
  nlohmann::json& report = out.report;
  report = {{"heights", nlohmann::json::array()},
            {"distances", nlohmann::json::array()},
            {"areas", nlohmann::json::array()},
            {"lesions", nlohmann::json::array()}};
  cancel.ThrowIfRequested("the surface's index");
  const SurfaceQuery surface(mesh);
  for (const Eigen::Vector2d& xy : plan.heights) {
    cancel.ThrowIfRequested("the heights");
    const Measured h = HeightAboveBase(surface, xy);
    out.rows.push_back({"height at " + PointText(xy), h, "mm"});
    report["heights"].push_back({{"at", {xy.x(), xy.y()}}, {"height_mm", ToJson(h)}});
  }
  for (const auto& d : plan.distances) {
    cancel.ThrowIfRequested("the distances");
    const GeodesicResult g = GeodesicDistance(surface, d[0], d[1]);
    const std::string between = PointText(d[0]) + "-" + PointText(d[1]);
    out.rows.push_back({"straight " + between, g.straight_mm, "mm"});
    out.rows.push_back({"along surface " + between, g.distance_mm, "mm"});
    nlohmann::json entry = ToJson(g);
    entry["from"] = {d[0].x(), d[0].y()};
    entry["to"] = {d[1].x(), d[1].y()};
    report["distances"].push_back(entry);
  }
  for (size_t i = 0; i < plan.areas.size(); ++i) {
    cancel.ThrowIfRequested("the areas");
    const Measured a = SurfaceArea(surface, plan.areas[i]);
    out.rows.push_back({"area of region " + std::to_string(i + 1), a, "mm^2"});
    report["areas"].push_back({{"region", PolygonJson(plan.areas[i])}, {"area_mm2", ToJson(a)}});
  }
  for (size_t i = 0; i < plan.lesions.size(); ++i) {
    cancel.ThrowIfRequested("the lesions");
    LesionMeasurement m;
    if (!plan.baseline) {
      m = MeasureLesion(surface, plan.lesions[i], plan.lesion);
    } else {
      try {
        m = MeasureLesionAgainstBaseline(surface, *plan.baseline, plan.lesions[i], plan.lesion,
                                         plan.baseline_params);
      } catch (const MeasurementError& e) {
        throw MeasurementError("against " + plan.baseline_name + ": " + e.what());
      }
    }
    for (ReportRow row : Rows(m)) {
      row.name = "lesion " + std::to_string(i + 1) + ": " + row.name;
      out.rows.push_back(row);
    }
    nlohmann::json entry = ToJson(m);
    entry["region"] = PolygonJson(plan.lesions[i]);
    report["lesions"].push_back(entry);
  }
  report["rows"] = ToJson(out.rows);
  return out;
}

}  // namespace bsls::measurement
