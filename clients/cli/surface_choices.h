// How the surface is made from a side's decode, as `bsls process` and
// `bsls reconstruct` take it on the command line: the light-plane model,
// the mesh strips and smoothing along the lines, put into the request to
// the processing service (in this process or another).
#ifndef BSLS_CLIENTS_CLI_SURFACE_CHOICES_H_
#define BSLS_CLIENTS_CLI_SURFACE_CHOICES_H_

#include <CLI/CLI.hpp>
#include <string>

#include "bsls/v1/processing.pb.h"

namespace bsls::cli {

struct SurfaceChoices {
  std::string plane_model = "perspective";  // or "parallel"
  std::string strips = "stitched";          // or "rows"
  bool smooth = false;
};

// Adds --plane-model, --strips and --smooth to `cmd`, read into *choices.
void AddSurfaceChoices(CLI::App* cmd, SurfaceChoices* choices);

// Sets the light planes, mesh strips and smoothing in *options.
void ApplySurfaceChoices(const SurfaceChoices& choices, v1::SurfaceOptions* options);

}  // namespace bsls::cli

#endif  // BSLS_CLIENTS_CLI_SURFACE_CHOICES_H_
