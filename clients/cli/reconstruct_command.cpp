// bsls reconstruct: both sides of a face, from their frames and calibrations
// to one joined surface (thesis 5.2): each side decoded and reconstructed
// with its calibration, then the two joined along the reference line — merged
// directly when the calibrations share a world frame (contracts section 4),
// otherwise matched on the common line's nose and mouth (thesis 5.2.2) and
// refined by ICP. The seam error is reported either way.
#include <cmath>
#include <cstdio>
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>

#include "bsls/common/atomic_file.h"
#include "bsls/contract/frame_message.h"
#include "bsls/io/frame_file.h"
#include "command.h"
#include "daemon_connection.h"
#include "processing_route.h"
#include "surface_choices.h"

namespace bsls::cli {
namespace {

struct ReconstructOptions {
  std::string left_image;
  std::string right_image;
  std::string left_calibration;
  std::string right_calibration;
  std::string output;
  std::string left_surface;
  std::string right_surface;
  std::string report;
  std::string join = "auto";
  SurfaceChoices surface_choices;
  bool ascii = false;
  bool quiet = false;
  bool json = false;      // the report on stdout instead of the summary
  ServiceAddress server;  // target empty: the service in this process
};

// Loads one side's frame (saying when it was converted to 8-bit grey).
cv::Mat LoadFrame(const std::string& image) {
  io::FrameConversion conversion;
  cv::Mat frame = io::LoadGreyFrame(image, &conversion);
  if (conversion.converted())
    std::cerr << "bsls: note: " << image << ": " << conversion.Describe() << "\n";
  return frame;
}

// The run's summary on stdout, from its report (session::SessionReport).
void PrintSessionSummary(const nlohmann::json& report, const std::string& output) {
  for (const char* side : {"left", "right"}) {
    const nlohmann::json& s = report.at(side);
    std::printf("%-6s %s: %d junctions, %d vertices\n", (std::string(side) + ":").c_str(),
                s.at("image").get<std::string>().c_str(), s.at("junctions").get<int>(),
                s.at("vertices").get<int>());
  }
  const nlohmann::json& j = report.at("join");
  const bool by_features = j.at("method") == "features+icp";
  std::printf("join:  %s, seam RMS %.3f mm (max %.3f mm over %d samples)",
              by_features ? "nose/mouth features + ICP" : "shared world frame",
              j.at("seam_rms_mm").get<double>(), j.at("seam_max_mm").get<double>(),
              j.at("seam_samples").get<int>());
  if (by_features) {
    const auto& t = j.at("translation_mm");
    std::printf(", right side moved %.2f deg, %.2f mm in %d ICP steps",
                j.at("rotation_deg").get<double>(),
                std::hypot(t[0].get<double>(), t[1].get<double>(), t[2].get<double>()),
                j.at("icp_iterations").get<int>());
  }
  std::printf("\n%s: %d vertices, %d triangles, %.0f ms in all\n", output.c_str(),
              report.at("vertices").get<int>(), report.at("triangles").get<int>(),
              report.at("total_ms").get<double>());
}

void RunReconstruct(const ReconstructOptions& o) {
  v1::ReconstructSessionRequest request;
  contract::ToFrameMessage(LoadFrame(o.left_image), request.mutable_left());
  contract::ToFrameMessage(LoadFrame(o.right_image), request.mutable_right());
  *request.mutable_left_calibration() = processing::ProcessingClient::Inline(
      ReadCalibrationFile(o.left_calibration, "--calibration-left"));
  *request.mutable_right_calibration() = processing::ProcessingClient::Inline(
      ReadCalibrationFile(o.right_calibration, "--calibration-right"));
  request.set_join(o.join == "shared"     ? v1::ReconstructSessionRequest::JOIN_SHARED
                   : o.join == "features" ? v1::ReconstructSessionRequest::JOIN_FEATURES
                                          : v1::ReconstructSessionRequest::JOIN_AUTO);
  ApplySurfaceChoices(o.surface_choices, request.mutable_surface());
  request.mutable_surface()->set_ascii_ply(o.ascii);
  request.set_want_side_surfaces(!o.left_surface.empty() || !o.right_surface.empty());
  request.set_request_tag((o.left_image + " + " + o.right_image).substr(0, 256));

  ProcessingRoute route(o.server);
  const processing::WorkOutcome out =
      route.client().ReconstructSession(request, route.Progress(o.quiet || o.json));
  route.Check(out.status, o.left_image + " + " + o.right_image);
  for (const v1::SideSummary& s : out.result.sides())
    if (!s.q_absolute())
      std::cerr << "bsls: note: " << (s.side() == v1::SIDE_LEFT ? o.left_image : o.right_image)
                << ": q stays relative: " << s.rows_note() << "\n";
  nlohmann::json report = nlohmann::json::parse(out.files.at("report.json"));
  report["left"]["image"] = o.left_image;
  report["right"]["image"] = o.right_image;
  // Side surfaces first: the joined one, written last, says the run is complete.
  if (!o.left_surface.empty()) WriteSurfaceArtifact(o.left_surface, out.files, "left.ply");
  if (!o.right_surface.empty()) WriteSurfaceArtifact(o.right_surface, out.files, "right.ply");
  if (!o.report.empty()) WriteFileAtomically(o.report, report.dump(2) + "\n");
  WriteSurfaceArtifact(o.output, out.files, "surface.ply");
  if (o.json)
    std::cout << report.dump() << "\n";
  else
    PrintSessionSummary(report, o.output);
}

}  // namespace

void AddReconstructCommand(CLI::App& app) {
  auto opts = std::make_shared<ReconstructOptions>();
  CLI::App* cmd = app.add_subcommand(
      "reconstruct", "Reconstruct both sides of a face and join them into one surface (world mm)");
  cmd->add_option("--left", opts->left_image, "Frame of the left side")->required();
  cmd->add_option("--right", opts->right_image, "Frame of the right side")->required();
  cmd->add_option("--calibration-left", opts->left_calibration, "Calibration of the left side")
      ->required();
  cmd->add_option("--calibration-right", opts->right_calibration, "Calibration of the right side")
      ->required();
  cmd->add_option("-o,--output", opts->output, "Joined surface: .ply (binary), .obj or .stl")
      ->required();
  cmd->add_option("--left-surface", opts->left_surface, "Also write the left side's surface");
  cmd->add_option("--right-surface", opts->right_surface, "Also write the right side's surface");
  cmd->add_option("--report", opts->report, "Write a JSON report (per side, join, seam error)");
  cmd->add_option("--join", opts->join,
                  "auto (shared frame when the calibrations share one, else features), shared, "
                  "or features (thesis 5.2.2 + ICP)")
      ->check(CLI::IsMember({"auto", "shared", "features"}))
      ->capture_default_str();
  AddSurfaceChoices(cmd, &opts->surface_choices);
  cmd->add_flag("--ascii", opts->ascii, "Write ASCII PLY instead of binary");
  cmd->add_flag("-q,--quiet", opts->quiet, "No progress on stderr");
  cmd->add_flag("--json", opts->json, "Print the report as one JSON object instead of the summary");
  AddServerOptions(*cmd, opts->server);
  cmd->callback([opts] { RunReconstruct(*opts); });
}

}  // namespace bsls::cli
