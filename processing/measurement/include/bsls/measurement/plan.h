// A set of figures to measure on one surface, measured in one call: the
// shared core of `bsls measure` and the processing service's session
// measurements (thesis 7.2). Each figure carries its 1-sigma uncertainty;
// the outcome is the report's rows (for a table) and its JSON.
//
// Units and frame: world millimetres (contracts section 3); points and
// region vertices are world (x, y).
// Thread-safety: MeasurePlan is a pure function of its arguments.
#ifndef BSLS_MEASUREMENT_PLAN_H_
#define BSLS_MEASUREMENT_PLAN_H_

#include <Eigen/Core>
#include <array>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "bsls/common/cancellation.h"
#include "bsls/geometry/surface_mesh.h"
#include "bsls/measurement/baseline_registration.h"
#include "bsls/measurement/lesion_measure.h"
#include "bsls/measurement/report.h"
#include "bsls/measurement/surface_query.h"

namespace bsls::measurement {

struct MeasurementPlan {
  std::vector<Eigen::Vector2d> heights;                   // height above the base plane z = 0
  std::vector<std::array<Eigen::Vector2d, 2>> distances;  // straight and along the surface
  std::vector<Polygon2d> areas;                           // surface area inside (>= 3 points each)
  std::vector<Polygon2d> lesions;  // lump or cavity inside (>= 3 points each)
  LesionMeasureParams lesion;
  // An earlier scan of the same face the lesions are measured against
  // instead of a fitted ring (MeasureLesionAgainstBaseline).
  std::optional<geometry::SurfaceMesh> baseline;
  std::string baseline_name;  // names the baseline in errors and the report
  BaselineParams baseline_params;

  // True when nothing is asked for.
  bool empty() const;
  // True when every figure is well formed; otherwise names the first bad one.
  bool IsValid(std::string* error) const;
};

struct MeasurementOutcome {
  std::vector<ReportRow> rows;  // in the plan's order
  // {"heights": [...], "distances": [...], "areas": [...], "lesions": [...],
  //  "rows": [...]}; regions as [[x, y], ...].
  nlohmann::json report;
};

// Measures every figure of `plan` on `mesh`. Throws MeasurementError naming
// the figure and the reason (a point off the surface, a region with no
// ring...), std::invalid_argument for a plan that is not valid, and
// bsls::Cancelled when `cancel` asks to stop (asked before each figure).
MeasurementOutcome MeasurePlan(const geometry::SurfaceMesh& mesh, const MeasurementPlan& plan,
                               const Cancellation& cancel = {});

}  // namespace bsls::measurement

#endif  // BSLS_MEASUREMENT_PLAN_H_
