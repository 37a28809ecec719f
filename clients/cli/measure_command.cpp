// bsls measure: clinical figures on a reconstructed surface (thesis 7.2):
// heights above the base plane, straight and along-the-surface distances,
// areas of regions, and lumps or cavities against a reference surface fitted
// around them or against an earlier scan of the same face (--baseline). Every figure comes with its
// 1-sigma uncertainty; a plain table goes to stdout and, on request, a JSON report to a file.
//
// Points and regions are world (x, y) in millimetres (contracts section 3): a
// point is "X,Y"; a region is a closed polygon "X,Y X,Y X,Y ..." (>= 3 points).
#include <cmath>
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <tuple>
#include <vector>

#include "bsls/common/atomic_file.h"
#include "bsls/contract/processing_messages.h"
#include "bsls/measurement/plan.h"
#include "bsls/measurement/report.h"
#include "command.h"
#include "daemon_connection.h"
#include "processing_route.h"

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
  bool quiet = false;
  ServiceAddress server;  // target empty: measured in this process
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

measurement::ReferenceKind ParseReference(const std::string& name) {
  if (name == "plane") return measurement::ReferenceKind::kPlane;
  if (name == "quadric") return measurement::ReferenceKind::kQuadric;
  if (name == "cubic") return measurement::ReferenceKind::kCubic;
  throw CommandError(kExitUsage, "--reference " + name + ": must be plane, quadric or cubic");
}

// The figures of `plan`, measured by the processing service (here or the
// one --server names): the surface (and baseline) go up, measurements.json
// comes back; a table on stdout and the JSON report.
void MeasureOnService(const MeasureOptions& o, const measurement::MeasurementPlan& plan) {
  v1::MeasureRequest request;
  request.set_surface_ply(ReadInputFile(o.surface, "surface"));
  if (!o.baseline.empty()) request.set_baseline_ply(ReadInputFile(o.baseline, "--baseline"));
  request.set_baseline_shares_frame(!o.register_baseline);
  *request.mutable_measurements() = contract::ToProto(plan);
  request.set_request_tag(o.surface.substr(0, 256));
  ProcessingRoute route(o.server);
  const processing::WorkOutcome out = route.client().Measure(request, route.Progress(o.quiet));
  route.Check(out.status, o.surface);
  nlohmann::json report = {
      {"surface", o.surface},
      {"baseline", o.baseline.empty() ? nlohmann::json() : nlohmann::json(o.baseline)}};
  nlohmann::json measured = nlohmann::json::parse(out.files.at("measurements.json"));
  // The service's table has 2 decimals; the rows give the figures for ours.
  std::vector<measurement::ReportRow> rows;
  for (const nlohmann::json& row : measured.at("rows"))
    rows.push_back({row.at("name"),
                    {row.at("value").get<double>(), row.at("uncertainty").get<double>()},
                    row.at("unit")});
  measured.erase("table");
  report.update(measured);
  if (!o.json.empty()) WriteFileAtomically(o.json, report.dump(2) + "\n");
  std::cout << measurement::FormatTable(rows, o.decimals);
}

// Every requested figure, checked here and measured on the service.
void RunMeasure(const MeasureOptions& o) {
  if (o.heights.empty() && o.distances.empty() && o.areas.empty() && o.lesions.empty())
    throw CommandError(kExitUsage,
                       "nothing to measure: give --height, --distance, --area or --lesion");
  if (!o.baseline.empty() && o.lesions.empty())
    throw CommandError(kExitUsage, "--baseline is the reference of --lesion: give a --lesion");
  measurement::MeasurementPlan plan;
  plan.lesion.reference = ParseReference(o.reference);
  plan.lesion.ring_width_mm = o.ring_mm;
  std::string why;
  if (!plan.lesion.IsValid(&why)) throw CommandError(kExitUsage, "--ring: " + why);
  // Parse everything before the (slow) work so a typo fails at once.
  for (const std::string& h : o.heights) {
    const auto points = ParsePoints(h, "--height");
    if (points.size() != 1) throw CommandError(kExitUsage, "--height \"" + h + "\": give one X,Y");
    plan.heights.push_back(points[0]);
  }
  for (const std::string& d : o.distances) {
    const auto points = ParsePoints(d, "--distance");
    if (points.size() != 2)
      throw CommandError(kExitUsage, "--distance \"" + d + "\": give two points \"X,Y X,Y\"");
    plan.distances.push_back({points[0], points[1]});
  }
  for (const auto& [texts, regions, option] : {std::tuple{&o.areas, &plan.areas, "--area"},
                                               std::tuple{&o.lesions, &plan.lesions, "--lesion"}})
    for (const std::string& text : *texts) {
      regions->push_back(ParsePoints(text, option));
      if (regions->back().size() < 3)
        throw CommandError(kExitUsage, std::string(option) + " \"" + text +
                                           "\": a region needs at least 3 points");
    }
  plan.baseline_params.register_rigidly = o.register_baseline;
  MeasureOnService(o, plan);
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
  cmd->add_flag("-q,--quiet", options->quiet, "No progress on stderr");
  AddServerOptions(*cmd, options->server);
  cmd->callback([options] { RunMeasure(*options); });
}

}  // namespace bsls::cli
