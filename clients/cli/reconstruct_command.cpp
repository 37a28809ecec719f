// bsls reconstruct: both sides of a face, from their frames and calibrations
// to one joined surface (thesis 5.2): each side decoded and reconstructed
// with its calibration, then the two joined along the reference line — merged
// directly when the calibrations share a world frame (contracts section 4),
// otherwise matched on the common line's nose and mouth (thesis 5.2.2) and
// refined by ICP. The seam error is reported either way.
#include <Eigen/Geometry>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>

#include "bsls/calibration/side_calibration.h"
#include "bsls/io/frame_file.h"
#include "bsls/io/surface_file.h"
#include "bsls/joining/join.h"
#include "bsls/reconstruction/side_pipeline.h"
#include "command.h"

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
  std::string plane_model = "perspective";
  bool smooth = false;
  bool ascii = false;
};

struct Side {
  reconstruction::SideOutcome outcome;
  std::string image;
};

// Decodes and reconstructs one side; CommandError naming the image otherwise.
Side ReconstructSide(const std::string& image, pattern::Side side,
                     const calibration::SideCalibration& calibration,
                     const reconstruction::SidePipelineParams& params) {
  cv::Mat frame;
  Side result{ProcessFrame(image, side, &calibration, params, &frame), image};
  if (!result.outcome.decode.ok)
    throw CommandError(kExitNotProcessed, image + ": " + result.outcome.decode.error);
  if (!result.outcome.decode.q_absolute)
    std::cerr << "bsls: note: " << image << ": q stays relative: " << result.outcome.rows_note
              << "\n";
  return result;
}

nlohmann::json SideJson(const Side& s) {
  const reconstruction::ReconstructionReport& r = s.outcome.report;
  return {{"image", s.image},
          {"junctions", s.outcome.decode.junctions.size()},
          {"lines", s.outcome.decode.lines.size()},
          {"q_absolute", s.outcome.decode.q_absolute},
          {"vertices", r.vertices},
          {"triangles", r.triangles},
          {"bridged", r.bridged_samples},
          {"decode_ms", s.outcome.decode.times.total_ms},
          {"reconstruct_ms", r.time_ms}};
}

void RunReconstruct(const ReconstructOptions& o) {
  const auto start = std::chrono::steady_clock::now();
  const calibration::SideCalibration left_cal = LoadCalibrationFile(o.left_calibration);
  const calibration::SideCalibration right_cal = LoadCalibrationFile(o.right_calibration);
  if (left_cal.side != pattern::Side::kLeft)
    throw CommandError(kExitInput, o.left_calibration + ": is a calibration of the right side");
  if (right_cal.side != pattern::Side::kRight)
    throw CommandError(kExitInput, o.right_calibration + ": is a calibration of the left side");
  std::string why;
  const bool shared = calibration::SharesWorldFrame(left_cal, right_cal, &why);
  if (o.join == "shared" && !shared)
    throw CommandError(kExitInput, o.left_calibration + " and " + o.right_calibration +
                                       " do not share a world frame: " + why);
  const bool by_features = o.join == "features" || (o.join == "auto" && !shared);

  reconstruction::SidePipelineParams params;
  params.planes = o.plane_model == "parallel" ? reconstruction::PlaneModelKind::kParallel
                                              : reconstruction::PlaneModelKind::kPerspective;
  params.reconstruction.smooth_lines = o.smooth;
  const Side left = ReconstructSide(o.left_image, pattern::Side::kLeft, left_cal, params);
  const Side right = ReconstructSide(o.right_image, pattern::Side::kRight, right_cal, params);

  joining::JoinResult joined;
  try {
    joined = by_features
                 ? joining::JoinByFeatures(*left.outcome.surface, *right.outcome.surface, {})
                 : joining::JoinSharedFrame(*left.outcome.surface, *right.outcome.surface, {});
  } catch (const joining::JoinError& e) {
    throw CommandError(kExitNotProcessed, o.left_image + " + " + o.right_image + ": " + e.what());
  }
  const auto encoding = o.ascii ? io::PlyEncoding::kAscii : io::PlyEncoding::kBinaryLittleEndian;
  const double total_ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();

  const Eigen::AngleAxisd rotation(joined.rotation);
  nlohmann::json report = {
      {"left", SideJson(left)},
      {"right", SideJson(right)},
      {"join",
       {{"method", by_features ? "features+icp" : "shared-frame"},
        {"shared_frame", shared},
        {"shared_frame_note", shared ? "" : why},
        {"seam_rms_mm", joined.seam.rms_mm},
        {"seam_max_mm", joined.seam.max_mm},
        {"seam_samples", joined.seam.samples},
        {"rotation_deg", rotation.angle() * 180.0 / M_PI},
        {"translation_mm",
         {joined.translation.x(), joined.translation.y(), joined.translation.z()}},
        {"icp_iterations", joined.iterations},
        {"zipper_triangles", joined.zipper_triangles}}},
      {"vertices", joined.mesh.VertexCount()},
      {"triangles", joined.mesh.faces.size()},
      {"total_ms", total_ms}};

  // Side surfaces first: the joined one, written last, says the run is complete.
  if (!o.left_surface.empty()) io::WriteSurface(o.left_surface, *left.outcome.surface, encoding);
  if (!o.right_surface.empty()) io::WriteSurface(o.right_surface, *right.outcome.surface, encoding);
  if (!o.report.empty()) io::WriteFileAtomically(o.report, report.dump(2) + "\n");
  io::WriteSurface(o.output, joined.mesh, encoding);

  std::printf("left:  %s: %zu junctions, %d vertices\n", o.left_image.c_str(),
              left.outcome.decode.junctions.size(), left.outcome.report.vertices);
  std::printf("right: %s: %zu junctions, %d vertices\n", o.right_image.c_str(),
              right.outcome.decode.junctions.size(), right.outcome.report.vertices);
  std::printf("join:  %s, seam RMS %.3f mm (max %.3f mm over %d samples)",
              by_features ? "nose/mouth features + ICP" : "shared world frame", joined.seam.rms_mm,
              joined.seam.max_mm, joined.seam.samples);
  if (by_features)
    std::printf(", right side moved %.2f deg, %.2f mm in %d ICP steps",
                rotation.angle() * 180.0 / M_PI, joined.translation.norm(), joined.iterations);
  std::printf("\n%s: %zu vertices, %zu triangles, %.0f ms in all\n", o.output.c_str(),
              joined.mesh.VertexCount(), joined.mesh.faces.size(), total_ms);
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
  cmd->add_option("--plane-model", opts->plane_model,
                  "Light planes: perspective (thesis 6.2.2, default) or parallel (6.2.1)")
      ->check(CLI::IsMember({"perspective", "parallel"}));
  cmd->add_flag("--smooth", opts->smooth, "Smooth along each line (thesis eq. 5.32) first");
  cmd->add_flag("--ascii", opts->ascii, "Write ASCII PLY instead of binary");
  cmd->callback([opts] { RunReconstruct(*opts); });
}

}  // namespace bsls::cli
