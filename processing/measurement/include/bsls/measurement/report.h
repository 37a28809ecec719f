// Measurement results as a JSON report and as a plain text table, for the
// command line and the services (units in every key or column).
#ifndef BSLS_MEASUREMENT_REPORT_H_
#define BSLS_MEASUREMENT_REPORT_H_

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "bsls/measurement/geodesic.h"
#include "bsls/measurement/lesion_measure.h"
#include "bsls/measurement/measures.h"

namespace bsls::measurement {

// One line of a report: a named figure with its unit ("mm", "mm^2", "mm^3").
struct ReportRow {
  std::string name;
  Measured measured;
  std::string unit;
};

// {"value": v, "uncertainty": s}.
nlohmann::json ToJson(const Measured& measured);
// Coefficients, origin, residual RMS and ring size of a reference.
nlohmann::json ToJson(const ReferenceSurface& reference);
// Distance, chord, discretisation estimate and path ([[x, y, z], ...]) in mm.
nlohmann::json ToJson(const GeodesicResult& result);
// Kind, peak (with position), level, area, volume, region area, reference.
nlohmann::json ToJson(const LesionMeasurement& result);
// The registration: matrix surface -> baseline, rotation angle, translation, pairs, RMS.
nlohmann::json ToJson(const BaselineRegistration& registration);
// [{"name": ..., "value": ..., "uncertainty": ..., "unit": ...}, ...].
nlohmann::json ToJson(const std::vector<ReportRow>& rows);

// The figures of a geodesic result as rows.
std::vector<ReportRow> Rows(const GeodesicResult& result);
// The figures of a lesion as rows ("lump height" or "cavity depth", ...).
std::vector<ReportRow> Rows(const LesionMeasurement& result);

// A fixed-width table: name, value, "+-" uncertainty, unit; one row per line,
// a header line first; values with `decimals` decimals.
std::string FormatTable(const std::vector<ReportRow>& rows, int decimals = 2);

}  // namespace bsls::measurement

#endif  // BSLS_MEASUREMENT_REPORT_H_
