#include "surface_choices.h"

namespace bsls::cli {

void AddSurfaceChoices(CLI::App* cmd, SurfaceChoices* choices) {
  cmd->add_option("--plane-model", choices->plane_model,
                  "Light planes: perspective (thesis 6.2.2, default) or parallel (6.2.1)")
      ->check(CLI::IsMember({"perspective", "parallel"}));
  cmd->add_option(
         "--strips", choices->strips,
         "Mesh strips: stitched (the samples facing each other, default; "
         "docs/reconstruction.md) or rows (the samples of the same image row, thesis 5.2.1)")
      ->check(CLI::IsMember({"rows", "stitched"}));
  cmd->add_flag("--smooth", choices->smooth, "Smooth along each line (thesis eq. 5.32) first");
}

void ApplySurfaceChoices(const SurfaceChoices& choices, v1::SurfaceOptions* options) {
  options->set_plane_model(choices.plane_model == "parallel"
                               ? v1::SurfaceOptions::PLANE_MODEL_PARALLEL
                               : v1::SurfaceOptions::PLANE_MODEL_PERSPECTIVE);
  options->set_strips(choices.strips == "rows" ? v1::SurfaceOptions::STRIP_METHOD_ROW_PAIRS
                                               : v1::SurfaceOptions::STRIP_METHOD_STITCHED);
  options->set_smooth_lines(choices.smooth);
}

}  // namespace bsls::cli
