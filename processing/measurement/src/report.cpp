#include "bsls/measurement/report.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <iomanip>
#include <numbers>
#include <sstream>

namespace bsls::measurement {

nlohmann::json ToJson(const Measured& measured) {
  return {{"value", measured.value}, {"uncertainty", measured.uncertainty}};
}

nlohmann::json ToJson(const ReferenceSurface& reference) {
  std::vector<double> coefficients(reference.coefficients.data(),
                                   reference.coefficients.data() + reference.coefficients.size());
  return {{"kind", ToString(reference.kind)},
          {"origin_xy_mm", {reference.origin.x(), reference.origin.y()}},
          {"coefficients", coefficients},
          {"residual_rms_mm", reference.residual_rms_mm},
          {"ring_vertices", reference.ring_vertices}};
}

nlohmann::json ToJson(const GeodesicResult& result) {
  nlohmann::json path = nlohmann::json::array();
  for (const auto& p : result.path) path.push_back({p.x(), p.y(), p.z()});
  return {{"geodesic_mm", ToJson(result.distance_mm)},
          {"straight_mm", ToJson(result.straight_mm)},
          {"discretisation_mm", result.discretisation_mm},
          {"path_mm", path}};
}

nlohmann::json ToJson(const BaselineRegistration& registration) {
  const Eigen::Matrix4d m = registration.transform.matrix();
  nlohmann::json matrix = nlohmann::json::array();
  for (int r = 0; r < 4; ++r) matrix.push_back({m(r, 0), m(r, 1), m(r, 2), m(r, 3)});
  return {{"rigid", registration.rigid},
          {"surface_to_baseline", matrix},
          {"rotation_deg",
           Eigen::AngleAxisd(registration.transform.linear()).angle() * 180.0 / std::numbers::pi},
          {"translation_mm", registration.transform.translation().norm()},
          {"iterations", registration.iterations},
          {"pairs", registration.pairs},
          {"rms_mm", registration.rms_mm}};
}

nlohmann::json ToJson(const LesionMeasurement& result) {
  const Eigen::Vector3d& p = result.peak_position;
  nlohmann::json out = {{"kind", result.cavity ? "cavity" : "lump"},
                        {result.cavity ? "depth_mm" : "height_mm", ToJson(result.peak_mm)},
                        {"peak_position_mm", {p.x(), p.y(), p.z()}},
                        {"level_mm", result.level_mm},
                        {"area_mm2", ToJson(result.area_mm2)},
                        {"volume_mm3", ToJson(result.volume_mm3)},
                        {"region_area_mm2", ToJson(result.region_area_mm2)},
                        {"region_vertices", result.region_vertices},
                        {"surface_coverage", result.surface_coverage},
                        {"holes_filled",
                         {{"area_mm2", ToJson(result.filled_area_mm2)},
                          {"volume_mm3", ToJson(result.filled_volume_mm3)},
                          {"share_of_region", result.filled_share}}},
                        {"reference", ToJson(result.reference)}};
  if (result.baseline) out["baseline"] = ToJson(*result.baseline);
  return out;
}

nlohmann::json ToJson(const std::vector<ReportRow>& rows) {
  nlohmann::json out = nlohmann::json::array();
  for (const ReportRow& row : rows)
    out.push_back({{"name", row.name},
                   {"value", row.measured.value},
                   {"uncertainty", row.measured.uncertainty},
                   {"unit", row.unit}});
  return out;
}

std::vector<ReportRow> Rows(const GeodesicResult& result) {
  return {{"geodesic distance", result.distance_mm, "mm"},
          {"straight distance", result.straight_mm, "mm"}};
}

std::vector<ReportRow> Rows(const LesionMeasurement& result) {
  std::vector<ReportRow> rows = {
      {result.cavity ? "cavity depth" : "lump height", result.peak_mm, "mm"},
      {result.cavity ? "cavity area" : "lump area", result.area_mm2, "mm^2"},
      {result.cavity ? "cavity volume" : "lump volume", result.volume_mm3, "mm^3"},
      {"region area", result.region_area_mm2, "mm^2"},
      {"region covered by the surface", {100.0 * result.surface_coverage, 0.0}, "%"},
      {result.cavity ? "cavity area, holes filled" : "lump area, holes filled",
       result.filled_area_mm2, "mm^2"},
      {result.cavity ? "cavity volume, holes filled" : "lump volume, holes filled",
       result.filled_volume_mm3, "mm^3"},
      {"region interpolated (holes filled)", {100.0 * result.filled_share, 0.0}, "%"},
      {"reference residual RMS", {result.reference.residual_rms_mm, 0.0}, "mm"}};
  if (result.baseline)
    rows.push_back({"baseline registration RMS", {result.baseline->rms_mm, 0.0}, "mm"});
  return rows;
}

std::string FormatTable(const std::vector<ReportRow>& rows, int decimals) {
  std::size_t name_width = 4;
  for (const ReportRow& row : rows) name_width = std::max(name_width, row.name.size());
  std::ostringstream out;
  out << std::left << std::setw(static_cast<int>(name_width)) << "what"
      << "  " << std::right << std::setw(12) << "value"
      << "     " << std::setw(10) << "1-sigma"
      << "  unit\n";
  out << std::fixed << std::setprecision(decimals);
  for (const ReportRow& row : rows)
    out << std::left << std::setw(static_cast<int>(name_width)) << row.name << "  " << std::right
        << std::setw(12) << row.measured.value << "  +- " << std::setw(10)
        << row.measured.uncertainty << "  " << row.unit << "\n";
  return out.str();
}

}  // namespace bsls::measurement
