// Renders the thesis scenes (default: face, both sides, noise 3) to PNG files
// plus their ground truth as JSON, for a human to look at:
//   simulator_preview [output_dir [kind ...]]    kinds: plane ramp ball face bunny
#include <chrono>
#include <exception>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <opencv2/imgcodecs.hpp>
#include <string>
#include <vector>

#include "bsls/simulator/renderer.h"
#include "bsls/simulator/scene.h"

int main(int argc, char** argv) {
  namespace sim = bsls::simulator;
  namespace pat = bsls::pattern;
  try {
    const std::filesystem::path out_dir = argc > 1 ? argv[1] : "/tmp/sim_preview";
    std::vector<sim::SurfaceKind> kinds;
    for (int i = 2; i < argc; ++i) {
      const auto kind = sim::ParseSurfaceKind(argv[i]);
      if (!kind) {
        std::cerr << "simulator_preview: unknown surface kind '" << argv[i] << "'\n";
        return 2;
      }
      kinds.push_back(*kind);
    }
    if (kinds.empty()) kinds.push_back(sim::SurfaceKind::kFace);
    std::filesystem::create_directories(out_dir);
    sim::RenderParams params;
    params.noise_sigma = 3.0;
    for (const sim::SurfaceKind kind : kinds) {
      for (const pat::Side side : {pat::Side::kLeft, pat::Side::kRight}) {
        const sim::Scene scene = sim::ThesisScene(side, kind);
        const auto start = std::chrono::steady_clock::now();
        const sim::Frame frame = sim::Render(scene, params);
        const double seconds =
            std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        const std::string stem =
            std::string(sim::ToString(kind)) + "_" + std::string(pat::ToString(side));
        const auto png = out_dir / (stem + ".png");
        if (!cv::imwrite(png.string(), frame.image)) {
          std::cerr << "simulator_preview: cannot write " << png << "\n";
          return 1;
        }
        std::ofstream(out_dir / (stem + "_truth.json")) << sim::ToJson(frame.truth).dump(1) << "\n";
        int visible = 0;
        for (const auto& j : frame.truth.junctions) visible += j.visible ? 1 : 0;
        double max_grey = 0.0;
        cv::minMaxLoc(frame.image, nullptr, &max_grey);
        std::cout << png.string() << ": " << seconds << " s, " << visible << " visible junctions, "
                  << frame.truth.lines.size() << " lines, max grey " << max_grey << "\n";
      }
    }
  } catch (const std::exception& e) {
    std::cerr << "simulator_preview: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
