// bsls measure: clinical figures on a reconstructed surface (thesis 7.2):
// heights above the base plane, straight and along-the-surface distances,
// areas of regions, and lumps or cavities against a reference surface fitted
// around them or against an earlier scan of the same face (--baseline). Every figure comes with its 1-sigma uncertainty; a plain table
// goes to stdout and, on request, a JSON report to a file.
//
// Points and regions are world (x, y) in millimetres (contracts section 3): a
// point is "X,Y"; a region is a closed polygon "X,Y X,Y X,Y ..." (>= 3 points).
#include <cmath>
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "bsls/io/frame_file.h"
#include "bsls/io/surface_file.h"
#include "bsls/measurement/geodesic.h"
#include "bsls/measurement/lesion_measure.h"
#include "bsls/measurement/measures.h"
#include "bsls/measurement/report.h"
#include "command.h"

namespace bsls::cli {
namespace {

struct MeasureOptions {
  std::string surface;
  std::vector<std::string> heights;    // "X,Y"
  std::vector<std::string> distances;  // "X,Y X,Y"
  std::vector<std::string> areas;      // polygons
  std::vector<std::string> lesions;    // polygons
  std::string reference = "cubic";
  double ring_mm = 10.0;
  std::string baseline;  // earlier scan the lesions are measured against
  bool register_baseline = true;
  std::string json;
  int decimals = 2;
};

// Parses "X,Y X,Y ..." (commas between coordinates, spaces or semicolons
// between points) for the option `option`.
std::vector<Eigen::Vector2d> ParsePoints(const std::string& text, const std::string& option) {
  std::string spaced = text;
  for (char& c : spaced)
    if (c == ';') c = ' ';
  std::istringstream in(spaced);
  std::vector<Eigen::Vector2d> points;
  std::string token;
  while (in >> token) {
    const size_t comma = token.find(',');
    double x = 0.0, y = 0.0;
    size_t used_x = 0, used_y = 0;
    try {
      if (comma == std::string::npos) throw std::invalid_argument("no comma");
      x = std::stod(token.substr(0, comma), &used_x);
      y = std::stod(token.substr(comma + 1), &used_y);
    } catch (const std::exception&) {
      used_x = 0;
    }
    if (used_x != comma || used_y != token.size() - comma - 1 || !std::isfinite(x) ||
        !std::isfinite(y))
      throw CommandError(kExitUsage, option + " \"" + text + "\": \"" + token +
                                         "\" is not a point X,Y in millimetres");
    points.emplace_back(x, y);
  }
  return points;
}

std::string PointText(const Eigen::Vector2d& p) {
  std::ostringstream out;
  out << "(" << p.x() << ", " << p.y() << ")";
  return out.str();
}

measurement::ReferenceKind ParseReference(const std::string& name) {
  if (name == "plane") return measurement::ReferenceKind::kPlane;
  if (name == "quadric") return measurement::ReferenceKind::kQuadric;
  if (name == "cubic") return measurement::ReferenceKind::kCubic;
  throw CommandError(kExitUsage, "--reference " + name + ": must be plane, quadric or cubic");
}

// Every requested figure, measured; rows for the table and the JSON report.
void RunMeasure(const MeasureOptions& o) {
  if (o.heights.empty() && o.distances.empty() && o.areas.empty() && o.lesions.empty())
    throw CommandError(kExitUsage,
                       "nothing to measure: give --height, --distance, --area or --lesion");
  measurement::LesionMeasureParams lesion_params;
  lesion_params.reference = ParseReference(o.reference);
  lesion_params.ring_width_mm = o.ring_mm;
  std::string why;
  if (!lesion_params.IsValid(&why)) throw CommandError(kExitUsage, "--ring: " + why);
  // Parse everything before the (slow) work so a typo fails at once.
  std::vector<Eigen::Vector2d> heights;
  for (const std::string& h : o.heights) {
    const auto points = ParsePoints(h, "--height");
    if (points.size() != 1) throw CommandError(kExitUsage, "--height \"" + h + "\": give one X,Y");
    heights.push_back(points[0]);
  }
  std::vector<std::vector<Eigen::Vector2d>> distances, areas, lesions;
  for (const std::string& d : o.distances) {
    distances.push_back(ParsePoints(d, "--distance"));
    if (distances.back().size() != 2)
      throw CommandError(kExitUsage, "--distance \"" + d + "\": give two points \"X,Y X,Y\"");
  }
  for (const std::string& a : o.areas) {
    areas.push_back(ParsePoints(a, "--area"));
    if (areas.back().size() < 3)
      throw CommandError(kExitUsage, "--area \"" + a + "\": a region needs at least 3 points");
  }
  for (const std::string& l : o.lesions) {
    lesions.push_back(ParsePoints(l, "--lesion"));
    if (lesions.back().size() < 3)
      throw CommandError(kExitUsage, "--lesion \"" + l + "\": a region needs at least 3 points");
  }

  if (!o.baseline.empty() && lesions.empty())
    throw CommandError(kExitUsage, "--baseline is the reference of --lesion: give a --lesion");
  measurement::BaselineParams baseline_params;
  baseline_params.register_rigidly = o.register_baseline;
  const geometry::SurfaceMesh mesh = io::ReadPly(o.surface);
  const geometry::SurfaceMesh baseline =
      o.baseline.empty() ? geometry::SurfaceMesh{} : io::ReadPly(o.baseline);
  std::vector<measurement::ReportRow> rows;
  nlohmann::json report = {{"surface", o.surface},
                           {"baseline", o.baseline.empty() ? nlohmann::json() : nlohmann::json(o.baseline)},
                           {"heights", nlohmann::json::array()},
                           {"distances", nlohmann::json::array()},
                           {"areas", nlohmann::json::array()},
                           {"lesions", nlohmann::json::array()}};
  try {
    const measurement::SurfaceQuery surface(mesh);
    for (const Eigen::Vector2d& xy : heights) {
      const measurement::Measured h = measurement::HeightAboveBase(surface, xy);
      rows.push_back({"height at " + PointText(xy), h, "mm"});
      report["heights"].push_back(
          {{"at", {xy.x(), xy.y()}}, {"height_mm", measurement::ToJson(h)}});
    }
    for (const auto& d : distances) {
      const measurement::GeodesicResult g = measurement::GeodesicDistance(surface, d[0], d[1]);
      const std::string between = PointText(d[0]) + "-" + PointText(d[1]);
      rows.push_back({"straight " + between, g.straight_mm, "mm"});
      rows.push_back({"along surface " + between, g.distance_mm, "mm"});
      nlohmann::json entry = measurement::ToJson(g);
      entry["from"] = {d[0].x(), d[0].y()};
      entry["to"] = {d[1].x(), d[1].y()};
      report["distances"].push_back(entry);
    }
    for (size_t i = 0; i < areas.size(); ++i) {
      const measurement::Measured a = measurement::SurfaceArea(surface, areas[i]);
      rows.push_back({"area of region " + std::to_string(i + 1), a, "mm^2"});
      report["areas"].push_back({{"region", o.areas[i]}, {"area_mm2", measurement::ToJson(a)}});
    }
    for (size_t i = 0; i < lesions.size(); ++i) {
      measurement::LesionMeasurement m;
      if (o.baseline.empty()) {
        m = measurement::MeasureLesion(surface, lesions[i], lesion_params);
      } else {
        try {
          m = measurement::MeasureLesionAgainstBaseline(surface, baseline, lesions[i],
                                                        lesion_params, baseline_params);
        } catch (const measurement::MeasurementError& e) {
          throw measurement::MeasurementError("against " + o.baseline + ": " + e.what());
        }
      }
      for (measurement::ReportRow row : measurement::Rows(m)) {
        row.name = "lesion " + std::to_string(i + 1) + ": " + row.name;
        rows.push_back(row);
      }
      nlohmann::json entry = measurement::ToJson(m);
      entry["region"] = o.lesions[i];
      report["lesions"].push_back(entry);
    }
  } catch (const measurement::MeasurementError& e) {
    throw CommandError(kExitNotProcessed, o.surface + ": " + e.what());
  }
  report["rows"] = measurement::ToJson(rows);
  if (!o.json.empty()) io::WriteFileAtomically(o.json, report.dump(2) + "\n");
  std::cout << measurement::FormatTable(rows, o.decimals);
}

}  // namespace

void AddMeasureCommand(CLI::App& app) {
  auto options = std::make_shared<MeasureOptions>();
  CLI::App* cmd = app.add_subcommand(
      "measure",
      "Measure a surface (thesis 7.2): heights, distances, areas, lumps and cavities, each with "
      "its uncertainty. Points are world X,Y in mm; regions are polygons \"X,Y X,Y X,Y ...\".");
  cmd->add_option("surface", options->surface, "Surface (PLY, world mm)")->required();
  cmd->add_option("--height", options->heights, "Height above the base plane z = 0 at X,Y");
  cmd->add_option("--distance", options->distances,
                  "Straight and along-the-surface distance between two points \"X,Y X,Y\"");
  cmd->add_option("--area", options->areas, "Surface area inside a region");
  cmd->add_option("--lesion", options->lesions,
                  "A lump or cavity inside a region: peak height/depth, area, volume against a "
                  "reference fitted to a ring around it");
  cmd->add_option("--reference", options->reference,
                  "Reference surface of --lesion: plane, quadric or cubic")
      ->capture_default_str();
  cmd->add_option("--ring", options->ring_mm, "Width of the ring around a --lesion region, mm")
      ->capture_default_str();
  cmd->add_option("--baseline", options->baseline,
                  "Measure --lesion against this earlier scan of the same face (PLY) instead of "
                  "a fitted ring: registered onto the surface outside the region");
  cmd->add_flag("!--no-register", options->register_baseline,
                "With --baseline: the scans share one frame, do not register them");
  cmd->add_option("--json", options->json, "Also write the report as JSON to this file");
  cmd->add_option("--decimals", options->decimals, "Decimals in the table")
      ->check(CLI::Range(0, 6))
      ->capture_default_str();
  cmd->callback([options] { RunMeasure(*options); });
}

}  // namespace bsls::cli
