// bsls process: decode one frame into labelled junctions and lines; with a
// calibration (or the thesis's explicit set-up), also its surface in world
// millimetres.
#include <cstdio>
#include <fstream>
#include <iostream>
#include <optional>
#include <string>

#include "bsls/calibration/calibration_file.h"
#include "bsls/common/atomic_file.h"
#include "bsls/decoder/decode_output.h"
#include "bsls/decoder/decoder.h"
#include "bsls/io/frame_file.h"
#include "bsls/io/surface_file.h"
#include "bsls/reconstruction/side_pipeline.h"
#include "bsls/rpc/frame_message.h"
#include "command.h"
#include "daemon_connection.h"
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
  ServiceAddress server;  // target empty: the work is done here
};

}  // namespace

reconstruction::SideOutcome ProcessFrame(const std::string& image, pattern::Side side,
                                         const reconstruction::SideGeometry& geometry,
                                         const reconstruction::SidePipelineParams& params,
                                         cv::Mat* frame) {
  io::FrameConversion conversion;
  *frame = io::LoadGreyFrame(image, &conversion);
  if (conversion.converted())
    std::cerr << "bsls: note: " << image << ": " << conversion.Describe() << "\n";
  try {
    return reconstruction::ProcessSide(*frame, side, geometry, params);
  } catch (const std::invalid_argument& e) {
    throw CommandError(kExitInput, image + ": " + e.what());
  } catch (const reconstruction::ReconstructionError& e) {
    throw CommandError(kExitNotProcessed, image + ": " + e.what());
  }
}

calibration::SideCalibration LoadCalibrationFile(const std::string& path) {
  try {
    return calibration::LoadCalibration(path).calibration;
  } catch (const calibration::CalibrationFileError& e) {
    throw CommandError(kExitInput, e.what());
  }
}

std::string ReadInputFile(const std::string& path, const std::string& option) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw CommandError(kExitInput, option + " " + path + ": cannot be read");
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

namespace {

// The same job on the processing service: the frame (converted here to 8-bit
// grey) and the calibration file go up, the contracts' files come back.
void RunProcessRemote(const ProcessOptions& o, pattern::Side side) {
  if (o.geometric_setup)
    throw CommandError(kExitUsage, "--geometric-setup runs here only: drop --server");
  if (!o.skeleton.empty())
    throw CommandError(kExitUsage, "--skeleton runs here only: drop --server");
  io::FrameConversion conversion;
  const cv::Mat frame = io::LoadGreyFrame(o.image, &conversion);
  if (conversion.converted())
    std::cerr << "bsls: note: " << o.image << ": " << conversion.Describe() << "\n";
  v1::ProcessFrameRequest request;
  rpc::ToFrameMessage(frame, request.mutable_frame());
  request.set_side(side == pattern::Side::kLeft ? v1::SIDE_LEFT : v1::SIDE_RIGHT);
  if (!o.calibration.empty())
    *request.mutable_calibration() =
        processing::ProcessingClient::Inline(ReadInputFile(o.calibration, "--calibration"));
  request.set_want_surface(!o.surface.empty());
  request.set_want_overlay(!o.overlay.empty());
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

  processing::ProcessingClient client = OpenProcessingClient(o.server);
  const processing::WorkOutcome out =
      client.ProcessFrame(request, ProgressPrinter(o.quiet || o.json_summary));
  CheckWork(out.status, o.image, o.server);
  const v1::SideSummary& s = out.result.sides(0);
  if (!o.calibration.empty() && !s.q_absolute())
    std::cerr << "bsls: note: " << o.image << ": q stays relative: " << s.rows_note() << "\n";
  WriteFileAtomically(o.junctions, out.files.at("junctions.json"));
  if (!o.overlay.empty()) WriteFileAtomically(o.overlay, out.files.at("overlay.png"));
  if (!o.surface.empty()) WriteFileAtomically(o.surface, out.files.at("surface.ply"));
  double total_ms = 0;
  for (const v1::StageTime& t : out.result.times())
    if (t.stage() == "decode") total_ms = t.ms();
  if (o.json_summary) {
    nlohmann::json j = {{"image", o.image},
                        {"side", o.side},
                        {"junctions", s.junctions()},
                        {"interpolated", s.interpolated_junctions()},
                        {"unlabelled", s.unlabelled_junctions()},
                        {"lines", s.lines()},
                        {"q_absolute", s.q_absolute()},
                        {"repairs", s.repairs()},
                        {"time_ms", total_ms},
                        {"replica", out.result.replica()},
                        {"attempts", out.attempts}};
    if (!o.surface.empty())
      j["surface"] = {{"vertices", s.vertices()},
                      {"triangles", s.triangles()},
                      {"bridged", s.bridged_samples()}};
    std::cout << j.dump() << "\n";
  } else {
    std::printf(
        "%s (%s): %u junctions (%u interpolated, %u unlabelled) on %u lines, %u repairs, "
        "q %s, %.1f ms on %s\n",
        o.image.c_str(), o.side.c_str(), s.junctions(), s.interpolated_junctions(),
        s.unlabelled_junctions(), s.lines(), s.repairs(), s.q_absolute() ? "absolute" : "relative",
        total_ms, out.result.replica().c_str());
    if (!o.surface.empty())
      std::printf("%s: %u vertices (%u bridged), %u triangles\n", o.surface.c_str(), s.vertices(),
                  s.bridged_samples(), s.triangles());
  }
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
  if (!o.server.target.empty()) return RunProcessRemote(o, *side);
  reconstruction::SidePipelineParams params;
  params.decode.extraction.method = o.method == "thesis" ? extraction::ExtractionMethod::kThesis
                                                         : extraction::ExtractionMethod::kModern;
  params.decode.interpretation.enable_repair = !o.no_repair;
  std::optional<decoder::DecodeChain> named;
  if (o.chain == "tracks") named = decoder::DecodeChain::kTracks;
  if (o.chain == "skeleton") named = decoder::DecodeChain::kSkeleton;
  std::string why;
  if (!decoder::ChainFor(named, params.decode, &why))
    throw CommandError(kExitUsage, "--chain tracks: " + why);
  params.chain = named;
  ApplySurfaceChoices(o.surface_choices, &params);
  params.reconstruct = !o.surface.empty();

  std::optional<calibration::SideCalibration> cal;
  reconstruction::SideGeometry geometry;
  if (!o.calibration.empty()) {
    cal = LoadCalibrationFile(o.calibration);
    geometry = &*cal;
  } else if (o.geometric_setup) {
    geometry = reconstruction::GeometricSetupParams{};
  }

  cv::Mat frame;
  const reconstruction::SideOutcome outcome =
      ProcessFrame(o.image, *side, geometry, params, &frame);
  const decoder::DecodeResult& result = outcome.decode;
  // The skeleton helps to see why a frame failed, so it is written either way.
  if (!o.skeleton.empty() && !result.skeleton.empty())
    io::WritePngAtomically(o.skeleton, result.skeleton);
  if (!result.ok) throw CommandError(kExitNotProcessed, o.image + ": " + result.error);
  if (cal && !result.q_absolute)
    std::cerr << "bsls: note: " << o.image << ": q stays relative: " << outcome.rows_note << "\n";

  WriteFileAtomically(o.junctions, decoder::ToJson(result).dump(1) + "\n");
  if (!o.overlay.empty()) io::WritePngAtomically(o.overlay, decoder::RenderOverlay(frame, result));
  if (outcome.surface)
    io::WriteSurface(o.surface, *outcome.surface,
                     o.ascii ? io::PlyEncoding::kAscii : io::PlyEncoding::kBinaryLittleEndian);

  int interpolated = 0;
  for (const auto& j : result.junctions) interpolated += j.interpolated;
  const reconstruction::ReconstructionReport& r = outcome.report;
  if (o.json_summary) {
    nlohmann::json s = {{"image", o.image},
                        {"side", o.side},
                        {"junctions", result.junctions.size()},
                        {"interpolated", interpolated},
                        {"unlabelled", result.unlabelled.size()},
                        {"lines", result.lines.size()},
                        {"q_absolute", result.q_absolute},
                        {"repairs", result.repairs},
                        {"label_conflicts", result.label_conflicts},
                        {"time_ms", result.times.total_ms},
                        {"extraction_ms", result.times.extraction_ms},
                        {"interpretation_ms", result.times.interpretation_ms},
                        {"subpixel_ms", result.times.subpixel_ms}};
    if (outcome.surface)
      s["surface"] = {
          {"vertices", r.vertices},       {"triangles", r.triangles},
          {"bridged", r.bridged_samples}, {"dropped_samples", r.dropped_samples},
          {"junctions", r.junctions},     {"junctions_by_projector", r.junctions_by_projector},
          {"time_ms", r.time_ms}};
    std::cout << s.dump() << "\n";
  } else {
    std::printf(
        "%s (%s): %zu junctions (%d interpolated, %zu unlabelled) on %zu lines, %d repairs, "
        "q %s, %.1f ms\n",
        o.image.c_str(), o.side.c_str(), result.junctions.size(), interpolated,
        result.unlabelled.size(), result.lines.size(), result.repairs,
        result.q_absolute ? "absolute" : "relative", result.times.total_ms);
    if (outcome.surface)
      std::printf("%s: %d vertices (%d bridged), %d triangles, %.1f ms\n", o.surface.c_str(),
                  r.vertices, r.bridged_samples, r.triangles, r.time_ms);
  }
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
  cmd->add_flag("-q,--quiet", opts->quiet, "With --server: no progress on stderr");
  AddServerOptions(*cmd, opts->server);
  cmd->callback([opts] { RunProcess(*opts); });
}

}  // namespace bsls::cli
