// One side from frame to surface: decode the grey frame (thesis 4-5), make
// its rows absolute through the calibration's projector matrix when it can
// (contracts section 2), and reconstruct the mesh (thesis 5.2). The chain the
// command-line tool and the processing service share.
//
// Frames and units: image pixels in, world millimetres out (contracts
// section 3).
// Thread-safety: ProcessSide is a pure function of its arguments.
#ifndef BSLS_RECONSTRUCTION_SIDE_PIPELINE_H_
#define BSLS_RECONSTRUCTION_SIDE_PIPELINE_H_

#include <opencv2/core.hpp>
#include <optional>
#include <string>
#include <variant>

#include "bsls/calibration/side_calibration.h"
#include "bsls/decoder/decoder.h"
#include "bsls/geometry/surface_mesh.h"
#include "bsls/reconstruction/calibrated_model.h"
#include "bsls/reconstruction/island_placement.h"
#include "bsls/reconstruction/reconstruction.h"

namespace bsls::reconstruction {

struct SidePipelineParams {
  // q_offset must stay unset: the calibration fixes it. Its `chain` is
  // replaced by the one below.
  decoder::DecodeParams decode;
  // The chain that decodes (decoder::ChainFor). nullopt: the track chain,
  // for labels and surfaces alike (it reports no label it cannot prove;
  // docs/decoding.md, "Which chain"), or the skeleton chain where `decode`
  // asks for its own options (the thesis's extraction, no repair). The
  // skeleton chain is the thesis's reference, named here or by those
  // options.
  std::optional<decoder::DecodeChain> chain;
  ReconstructionParams reconstruction;
  PlaneModelKind planes = PlaneModelKind::kPerspective;
  SlideRowParams rows;
  // With a calibration that has a projector matrix, the track chain places
  // the parts not joined to line 0 by the geometry (island_placement.h).
  IslandPlacementParams islands;
  bool reconstruct = true;  // false: decode (and absolute rows) only

  // True when every part is usable; otherwise names the part and why.
  bool IsValid(std::string* error) const;
};

// What a side gives without a calibration, with one, or with the thesis's
// explicit set-up (GeometricSetupParams) when there is no calibration.
using SideGeometry =
    std::variant<std::monostate, const calibration::SideCalibration*, GeometricSetupParams>;

struct SideOutcome {
  decoder::DecodeResult decode;  // ok == false: nothing else is set
  // Why the rows stayed relative although a calibration was given (empty
  // when they are absolute or no calibration was given).
  std::string rows_note;
  std::optional<geometry::SurfaceMesh> surface;  // when reconstructed
  ReconstructionReport report;
};

// Decodes `grey` of `side` and, with a geometry, reconstructs its surface.
// Throws ReconstructionError when the frame decodes but cannot be
// reconstructed, std::invalid_argument for invalid params or a calibration
// of the other side or another image size; a frame that does not decode comes
// back with decode.ok == false and its reason. Throws bsls::Cancelled when
// `cancel` asks to stop.
SideOutcome ProcessSide(const cv::Mat& grey, pattern::Side side, const SideGeometry& geometry,
                        const SidePipelineParams& params = {}, const Cancellation& cancel = {});

}  // namespace bsls::reconstruction

#endif  // BSLS_RECONSTRUCTION_SIDE_PIPELINE_H_
