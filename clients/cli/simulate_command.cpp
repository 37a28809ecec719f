// bsls simulate: render frames of the projected pattern on a simulated
// surface, with their exact ground truth.
#include <cstdio>
#include <iostream>
#include <string>

#include "bsls/io/frame_file.h"
#include "bsls/simulator/renderer.h"
#include "bsls/simulator/scene.h"
#include "command.h"

namespace bsls::cli {
namespace {

struct SimulateOptions {
  std::string surface = "face";
  std::string side = "left";
  std::string output;
  std::string truth;
  bool cross = false;
  double noise = 3.0;
  unsigned seed = 1;
  int size = 512;
  int supersampling = 3;
  bool eyebrows = true;
};

void RunSimulate(const SimulateOptions& o) {
  const auto side = pattern::ParseSide(o.side);
  if (!side) throw CommandError(kExitUsage, "--side must be left or right, not '" + o.side + "'");
  const auto kind = simulator::ParseSurfaceKind(o.surface);
  if (!kind) throw CommandError(kExitUsage, "unknown --surface '" + o.surface + "'");
  simulator::ThesisSceneOptions options;
  options.reference_cross = o.cross;
  options.face_eyebrows = o.eyebrows;
  options.rig.width = o.size;
  options.rig.height = o.size;
  simulator::Scene scene;
  try {
    scene = simulator::ThesisScene(*side, *kind, options);
  } catch (const simulator::MeshLoadError& e) {
    throw io::InputError(e.what());
  }
  simulator::RenderParams params;
  params.noise_sigma = o.noise;
  params.seed = o.seed;
  params.supersampling = o.supersampling;
  std::string why;
  if (!params.IsValid(&why)) throw CommandError(kExitUsage, why);
  const simulator::Frame frame = simulator::Render(scene, params);
  io::WritePngAtomically(o.output, frame.image);
  if (!o.truth.empty())
    io::WriteFileAtomically(o.truth, simulator::ToJson(frame.truth).dump(1) + "\n");
  int visible = 0;
  for (const auto& j : frame.truth.junctions) visible += j.visible;
  std::printf("%s: %s, %s side, %dx%d, noise %.1f, %d visible junctions\n", o.output.c_str(),
              o.surface.c_str(), o.side.c_str(), frame.image.cols, frame.image.rows, o.noise,
              visible);
}

}  // namespace

void AddSimulateCommand(CLI::App& app) {
  auto opts = std::make_shared<SimulateOptions>();
  CLI::App* cmd = app.add_subcommand(
      "simulate", "Render a frame of the pattern on a simulated surface, with ground truth");
  cmd->add_option("--surface", opts->surface, "plane, ramp, ball, face (default) or bunny");
  cmd->add_option("--side", opts->side, "left (default) or right");
  cmd->add_option("-o,--output", opts->output, "Output PNG (8-bit grey)")->required();
  cmd->add_option("--truth", opts->truth, "Output JSON of the exact junctions and lines");
  cmd->add_flag("--cross", opts->cross, "Project slide 1 (reference cross) instead of the bricks");
  cmd->add_option("--noise", opts->noise, "Sensor noise sigma, grey levels (default 3)")
      ->check(CLI::Range(0.0, 100.0));
  cmd->add_option("--seed", opts->seed, "Noise seed (default 1)");
  cmd->add_option("--size", opts->size, "Image width and height, pixels (default 512)")
      ->check(CLI::Range(64, 8192));
  cmd->add_option("--supersampling", opts->supersampling, "Rays per pixel and axis (default 3)")
      ->check(CLI::Range(1, 8));
  cmd->add_flag("!--no-eyebrows", opts->eyebrows, "Face: leave out the dark eyebrow patches");
  cmd->callback([opts] { RunSimulate(*opts); });
}

}  // namespace bsls::cli
