// bsls process: decode one frame into labelled junctions and lines.
#include <cstdio>
#include <iostream>
#include <string>

#include "bsls/decoder/decode_output.h"
#include "bsls/decoder/decoder.h"
#include "bsls/io/frame_file.h"
#include "command.h"

namespace bsls::cli {
namespace {

struct ProcessOptions {
  std::string image;
  std::string side;
  std::string junctions;
  std::string overlay;
  std::string skeleton;
  std::string method = "modern";
  bool no_repair = false;
  bool json_summary = false;
};

void RunProcess(const ProcessOptions& o) {
  const auto side = pattern::ParseSide(o.side);
  if (!side) throw CommandError(kExitUsage, "--side must be left or right, not '" + o.side + "'");
  decoder::DecodeParams params;
  params.extraction.method =
      o.method == "thesis" ? extraction::ExtractionMethod::kThesis : extraction::ExtractionMethod::kModern;
  params.interpretation.enable_repair = !o.no_repair;

  io::FrameConversion conversion;
  const cv::Mat frame = io::LoadGreyFrame(o.image, &conversion);
  if (conversion.converted()) std::cerr << "bsls: note: " << o.image << ": " << conversion.Describe() << "\n";

  const decoder::DecodeResult result = decoder::Decode(frame, *side, params);
  // The skeleton helps to see why a frame failed, so it is written either way.
  if (!o.skeleton.empty() && !result.skeleton.empty())
    io::WritePngAtomically(o.skeleton, result.skeleton);
  if (!result.ok) throw CommandError(kExitNotProcessed, o.image + ": " + result.error);

  io::WriteFileAtomically(o.junctions, decoder::ToJson(result).dump(1) + "\n");
  if (!o.overlay.empty()) io::WritePngAtomically(o.overlay, decoder::RenderOverlay(frame, result));

  int interpolated = 0;
  for (const auto& j : result.junctions) interpolated += j.interpolated;
  if (o.json_summary) {
    nlohmann::json s = {{"image", o.image},
                        {"side", o.side},
                        {"junctions", result.junctions.size()},
                        {"interpolated", interpolated},
                        {"lines", result.lines.size()},
                        {"repairs", result.repairs},
                        {"label_conflicts", result.label_conflicts},
                        {"time_ms", result.times.total_ms},
                        {"extraction_ms", result.times.extraction_ms},
                        {"interpretation_ms", result.times.interpretation_ms},
                        {"subpixel_ms", result.times.subpixel_ms}};
    std::cout << s.dump() << "\n";
  } else {
    std::printf("%s (%s): %zu junctions (%d interpolated) on %zu lines, %d repairs, %.1f ms\n",
                o.image.c_str(), o.side.c_str(), result.junctions.size(), interpolated,
                result.lines.size(), result.repairs, result.times.total_ms);
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
  cmd->add_option("--junctions", opts->junctions, "Output JSON of junctions and lines (contracts 5)")
      ->required();
  cmd->add_option("--overlay", opts->overlay, "Output PNG with the lines coloured by p");
  cmd->add_option("--skeleton", opts->skeleton, "Output PNG of the repaired one-pixel skeleton");
  cmd->add_option("--method", opts->method, "Feature extraction: modern (default) or thesis")
      ->check(CLI::IsMember({"modern", "thesis"}));
  cmd->add_flag("--no-repair", opts->no_repair, "Label what is seen; seal no discontinuity");
  cmd->add_flag("--json", opts->json_summary, "Print the summary as one JSON object");
  cmd->callback([opts] { RunProcess(*opts); });
}

}  // namespace bsls::cli
