// bsls process: decode one frame into labelled junctions and lines; with a
// calibration (or the thesis's explicit set-up), also its surface in world
// millimetres.
#include <cstdio>
#include <fstream>
#include <iostream>
#include <nlohmann/json.hpp>
#include <string>

#include "bsls/calibration/calibration_file.h"
#include "bsls/common/atomic_file.h"
#include "bsls/contract/frame_message.h"
#include "bsls/contract/processing_messages.h"
#include "bsls/io/frame_file.h"
#include "bsls/pattern/brick_pattern.h"
#include "command.h"
#include "daemon_connection.h"
#include "processing_route.h"
#include "surface_choices.h"

namespace bsls::cli {
namespace {

struct ProcessOptions {
  std::string image;
  std::string side;
  std::string junctions;
  std::string overlay;
  std::string skeleton;
  std::string method = "modern";
  std::string chain;  // empty: the decoder's choice (decoder::ChainFor)
  std::string calibration;
  std::string surface;
  SurfaceChoices surface_choices;
  bool geometric_setup = false;
  bool ascii = false;
  bool no_repair = false;
  bool json_summary = false;
  bool quiet = false;
  ServiceAddress server;  // target empty: the service in this process
};

}  // namespace

std::string ReadInputFile(const std::string& path, const std::string& option) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw CommandError(kExitInput, option + " " + path + ": cannot be read");
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

std::string ReadCalibrationFile(const std::string& path, const std::string& option) {
  std::string yaml = ReadInputFile(path, option);
  try {
    (void)calibration::CalibrationFromYaml(yaml, path);
  } catch (const calibration::CalibrationFileError& e) {
    throw CommandError(kExitInput, e.what());
  }
  return yaml;
}

namespace {

// The request the options ask for: the frame (converted here to 8-bit grey,
// saying so), the calibration file as it is, the options.
v1::ProcessFrameRequest ProcessRequest(const ProcessOptions& o, pattern::Side side) {
  io::FrameConversion conversion;
  const cv::Mat frame = io::LoadGreyFrame(o.image, &conversion);
  if (conversion.converted())
    std::cerr << "bsls: note: " << o.image << ": " << conversion.Describe() << "\n";
  v1::ProcessFrameRequest request;
  contract::ToFrameMessage(frame, request.mutable_frame());
  request.set_side(contract::ToProto(side));
  if (!o.calibration.empty())
    *request.mutable_calibration() =
        processing::ProcessingClient::Inline(ReadCalibrationFile(o.calibration, "--calibration"));
  request.set_geometric_setup(o.geometric_setup);
  request.set_want_surface(!o.surface.empty());
  request.set_want_overlay(!o.overlay.empty());
  request.set_want_skeleton(!o.skeleton.empty());
  request.mutable_decode()->set_method(o.method == "thesis" ? v1::DecodeOptions::METHOD_THESIS
                                                            : v1::DecodeOptions::METHOD_MODERN);
  request.mutable_decode()->set_no_repair(o.no_repair);
  request.mutable_decode()->set_chain(o.chain == "tracks" ? v1::DecodeOptions::CHAIN_TRACKS
                                      : o.chain == "skeleton"
                                          ? v1::DecodeOptions::CHAIN_SKELETON
                                          : v1::DecodeOptions::CHAIN_UNSPECIFIED);
  ApplySurfaceChoices(o.surface_choices, request.mutable_surface());
  request.mutable_surface()->set_ascii_ply(o.ascii);
  request.set_request_tag(o.image.substr(0, 256));
  return request;
}

// The wall time of `stage` in `result` (0 when it did not run).
double StageMs(const v1::Result& result, const std::string& stage) {
  for (const v1::StageTime& t : result.times())
    if (t.stage() == stage) return t.ms();
  return 0.0;
}

// The summary on stdout: one JSON object, or a line (two with a surface).
void PrintProcessSummary(const ProcessOptions& o, const processing::WorkOutcome& out, bool local) {
  const v1::SideSummary& s = out.result.sides(0);
  if (o.json_summary) {
    nlohmann::json j = {{"image", o.image},
                        {"side", o.side},
                        {"junctions", s.junctions()},
                        {"interpolated", s.interpolated_junctions()},
                        {"unlabelled", s.unlabelled_junctions()},
                        {"lines", s.lines()},
                        {"q_absolute", s.q_absolute()},
                        {"repairs", s.repairs()},
                        {"label_conflicts", s.label_conflicts()},
                        {"islands", s.islands()},
                        {"islands_placed", s.islands_placed()},
                        {"ruled_out", s.ruled_out()},
                        {"time_ms", StageMs(out.result, "decode")},
                        {"extraction_ms", StageMs(out.result, "extraction")},
                        {"interpretation_ms", StageMs(out.result, "interpretation")},
                        {"subpixel_ms", StageMs(out.result, "subpixel")},
                        {"replica", out.result.replica()},
                        {"attempts", out.attempts}};
    if (!o.surface.empty())
      j["surface"] = {{"vertices", s.vertices()},
                      {"triangles", s.triangles()},
                      {"bridged", s.bridged_samples()},
                      {"dropped_samples", s.dropped_samples()},
                      {"junctions", s.surface_junctions()},
                      {"junctions_by_projector", s.junctions_by_projector()},
                      {"time_ms", StageMs(out.result, "reconstruct")}};
    std::cout << j.dump() << "\n";
    return;
  }
  std::printf(
      "%s (%s): %u junctions (%u interpolated, %u unlabelled) on %u lines, %u repairs, "
      "q %s, %.1f ms%s\n",
      o.image.c_str(), o.side.c_str(), s.junctions(), s.interpolated_junctions(),
      s.unlabelled_junctions(), s.lines(), s.repairs(), s.q_absolute() ? "absolute" : "relative",
      StageMs(out.result, "decode"), local ? "" : (" on " + out.result.replica()).c_str());
  if (!o.surface.empty())
    std::printf("%s: %u vertices (%u bridged), %u triangles, %.1f ms\n", o.surface.c_str(),
                s.vertices(), s.bridged_samples(), s.triangles(),
                StageMs(out.result, "reconstruct"));
}

void RunProcess(const ProcessOptions& o) {
  const auto side = pattern::ParseSide(o.side);
  if (!side) throw CommandError(kExitUsage, "--side must be left or right, not '" + o.side + "'");
  if (!o.surface.empty() && o.calibration.empty() && !o.geometric_setup)
    throw CommandError(kExitUsage,
                       "--surface needs --calibration CAL (or --geometric-setup, the thesis's "
                       "uncalibrated height formula)");
  if (!o.calibration.empty() && o.geometric_setup)
    throw CommandError(kExitUsage, "--calibration and --geometric-setup exclude each other");
  if (o.chain == "tracks" && (o.method == "thesis" || o.no_repair))
    throw CommandError(kExitUsage,
                       "--chain tracks: --method thesis and --no-repair are the skeleton "
                       "chain's options");
  const v1::ProcessFrameRequest request = ProcessRequest(o, *side);

  ProcessingRoute route(o.server);
  const processing::WorkOutcome out =
      route.client().ProcessFrame(request, route.Progress(o.quiet || o.json_summary));
  // The skeleton helps to see why a frame failed, so it is written either way.
  if (!o.skeleton.empty() && out.files.count("skeleton.png"))
    WriteFileAtomically(o.skeleton, out.files.at("skeleton.png"));
  route.Check(out.status, o.image);
  const v1::SideSummary& s = out.result.sides(0);
  if ((!o.calibration.empty()) && !s.q_absolute())
    std::cerr << "bsls: note: " << o.image << ": q stays relative: " << s.rows_note() << "\n";
  WriteFileAtomically(o.junctions, out.files.at("junctions.json"));
  if (!o.overlay.empty()) WriteFileAtomically(o.overlay, out.files.at("overlay.png"));
  if (!o.surface.empty()) WriteSurfaceArtifact(o.surface, out.files, "surface.ply");
  PrintProcessSummary(o, out, route.local());
}

}  // namespace

void AddProcessCommand(CLI::App& app) {
  auto opts = std::make_shared<ProcessOptions>();
  CLI::App* cmd = app.add_subcommand(
      "process", "Decode one frame of the brick pattern into labelled junctions and lines");
  cmd->add_option("IMAGE", opts->image, "Frame to decode (8-bit grey PNG; others are converted)")
      ->required();
  cmd->add_option("--side", opts->side, "Side of the face: left or right")->required();
  cmd->add_option("--junctions", opts->junctions,
                  "Output JSON of junctions and lines (contracts 5)")
      ->required();
  cmd->add_option("--overlay", opts->overlay, "Output PNG with the lines coloured by p");
  cmd->add_option("--skeleton", opts->skeleton,
                  "Output PNG of what was traced: the repaired one-pixel skeleton, or the "
                  "track chain's tracks");
  cmd->add_option("--method", opts->method,
                  "Skeleton chain's feature extraction: modern (default) or thesis")
      ->check(CLI::IsMember({"modern", "thesis"}));
  cmd->add_option("--chain", opts->chain,
                  "Decoding chain: tracks (default: ridge points linked into tracks) or "
                  "skeleton (thinning and loop tracing, thesis ch. 4-5; the default with "
                  "--method thesis or --no-repair, its options); docs/decoding.md")
      ->check(CLI::IsMember({"skeleton", "tracks"}));
  cmd->add_option("--calibration", opts->calibration,
                  "Calibration of this side (bsls calibrate): absolute q and the surface");
  cmd->add_option("--surface", opts->surface,
                  "Output surface in world mm: .ply (binary), .obj or .stl; needs --calibration");
  cmd->add_flag("--geometric-setup", opts->geometric_setup,
                "No calibration: the thesis height formula (eq. 2.1-2.12) from the set-up of "
                "Tables 2.1/2.2 (a fallback: millimetres only as good as those distances)");
  AddSurfaceChoices(cmd, &opts->surface_choices);
  cmd->add_flag("--ascii", opts->ascii, "Write an ASCII PLY instead of binary");
  cmd->add_flag("--no-repair", opts->no_repair,
                "Skeleton chain: label what is seen; seal no discontinuity");
  cmd->add_flag("--json", opts->json_summary, "Print the summary as one JSON object");
  cmd->add_flag("-q,--quiet", opts->quiet, "No progress on stderr");
  AddServerOptions(*cmd, opts->server);
  cmd->callback([opts] { RunProcess(*opts); });
}

}  // namespace bsls::cli
