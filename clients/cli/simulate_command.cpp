// bsls simulate: render frames of the projected pattern on a simulated
// surface, with their exact ground truth.
#include <cmath>
#include <cstdio>
#include <iostream>
#include <sstream>
#include <string>
#include <vector>

#include "bsls/common/atomic_file.h"
#include "bsls/common/errors.h"
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
  std::vector<std::string> lesions;  // "X,Y,H,R[,R0]"
};

// Parses a --lesion "X,Y,H,R[,R0]" (mm): centre, signed height (< 0: a
// cavity), outer radius and flat-top radius (default R / 3).
simulator::LesionParams ParseLesion(const std::string& text) {
  std::vector<double> numbers;
  std::string field;
  std::istringstream in(text);
  bool ok = true;
  while (std::getline(in, field, ',')) {
    std::size_t used = 0;
    double value = 0.0;
    try {
      value = std::stod(field, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    ok = ok && used == field.size() && used > 0 && std::isfinite(value);
    numbers.push_back(value);
  }
  if (!ok || numbers.size() < 4 || numbers.size() > 5)
    throw CommandError(kExitUsage, "--lesion \"" + text +
                                       "\": give X,Y,H,R[,R0] in millimetres (H < 0: a cavity)");
  simulator::LesionParams lesion;
  lesion.centre_xy_mm = {numbers[0], numbers[1]};
  lesion.height_mm = numbers[2];
  lesion.radius_mm = numbers[3];
  lesion.top_radius_mm = numbers.size() == 5 ? numbers[4] : numbers[3] / 3.0;
  std::string why;
  if (!lesion.IsValid(&why)) throw CommandError(kExitUsage, "--lesion \"" + text + "\": " + why);
  return lesion;
}

void RunSimulate(const SimulateOptions& o) {
  const auto side = pattern::ParseSide(o.side);
  if (!side) throw CommandError(kExitUsage, "--side must be left or right, not '" + o.side + "'");
  const auto kind = simulator::ParseSurfaceKind(o.surface);
  if (!kind) throw CommandError(kExitUsage, "unknown --surface '" + o.surface + "'");
  simulator::ThesisSceneOptions options;
  options.reference_cross = o.cross;
  options.face_eyebrows = o.eyebrows;
  for (const std::string& lesion : o.lesions) options.face_lesions.push_back(ParseLesion(lesion));
  if (!options.face_lesions.empty() && *kind != simulator::SurfaceKind::kFace)
    throw CommandError(kExitUsage, "--lesion needs --surface face");
  options.rig.width = o.size;
  options.rig.height = o.size;
  simulator::Scene scene;
  try {
    scene = simulator::ThesisScene(*side, *kind, options);
  } catch (const simulator::MeshLoadError& e) {
    throw InputError(e.what());
  } catch (const std::invalid_argument& e) {  // overlapping lesions
    throw CommandError(kExitUsage, e.what());
  }
  simulator::RenderParams params;
  params.noise_sigma = o.noise;
  params.seed = o.seed;
  params.supersampling = o.supersampling;
  std::string why;
  if (!params.IsValid(&why)) throw CommandError(kExitUsage, why);
  const simulator::Frame frame = simulator::Render(scene, params);
  io::WritePngAtomically(o.output, frame.image);
  if (!o.truth.empty()) WriteFileAtomically(o.truth, simulator::ToJson(frame.truth).dump(1) + "\n");
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
  cmd->add_option("--lesion", opts->lesions,
                  "Face: a lump (H > 0) or cavity (H < 0) \"X,Y,H,R[,R0]\" in world mm "
                  "(thesis 7.2); repeat for more");
  cmd->callback([opts] { RunSimulate(*opts); });
}

}  // namespace bsls::cli
