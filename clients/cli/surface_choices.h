// How the surface is made from a side's decode, as `bsls process` and
// `bsls reconstruct` take it on the command line: the light-plane model,
// the mesh strips and smoothing along the lines. One set of flags, read the
// same way for the local pipeline and for the processing service.
#ifndef BSLS_CLIENTS_CLI_SURFACE_CHOICES_H_
#define BSLS_CLIENTS_CLI_SURFACE_CHOICES_H_

#include <CLI/CLI.hpp>
#include <string>

#include "bsls/reconstruction/side_pipeline.h"
#include "bsls/v1/processing.pb.h"

namespace bsls::cli {

struct SurfaceChoices {
  std::string plane_model = "perspective";  // or "parallel"
  std::string strips = "stitched";          // or "rows"
  bool smooth = false;
};

// Adds --plane-model, --strips and --smooth to `cmd`, read into *choices.
void AddSurfaceChoices(CLI::App* cmd, SurfaceChoices* choices);

// Sets the light planes, mesh strips and smoothing of *params (the local pipeline).
void ApplySurfaceChoices(const SurfaceChoices& choices, reconstruction::SidePipelineParams* params);

// Sets the same in *options (a request to the processing service).
void ApplySurfaceChoices(const SurfaceChoices& choices, v1::SurfaceOptions* options);

}  // namespace bsls::cli

#endif  // BSLS_CLIENTS_CLI_SURFACE_CHOICES_H_
