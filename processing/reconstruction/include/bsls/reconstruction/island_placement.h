// Islands placed by the geometry (docs/decoding.md, "Islands placed by the
// geometry"): a calibrated side's decoder::LabelGeometry.
//
// A part of the frame not joined to line 0 is labelled relative to itself;
// its labels are right up to one shift (dp, dq) with dp + dq even. Each
// candidate dp puts every junction on the light plane of its line (the
// perspective model, thesis 6.2.2) and the projector matrix (thesis eq.
// 2.16) says which slide row t it then came from. The right shift puts every
// junction on a whole row of the right parity; a wrong one moves the points
// along their epipolar lines in the slide, whose slope (the camera beside the
// projector) moves t in proportion to the row, so the rows no longer fit one
// shift. Candidates whose points leave the measuring volume (the
// calibration views' depth range, widened) are ruled out first. An island is
// placed only where one candidate fits and every other misses clearly;
// otherwise it stays unlabelled.
//
// Frames and units: world mm (contracts section 3), image pixels, slide rows.
// Thread-safety: the geometry is immutable; PlaceIsland may run on any thread.
#ifndef BSLS_RECONSTRUCTION_ISLAND_PLACEMENT_H_
#define BSLS_RECONSTRUCTION_ISLAND_PLACEMENT_H_

#include <memory>
#include <string>

#include "bsls/calibration/side_calibration.h"
#include "bsls/decoder/label_geometry.h"

namespace bsls::reconstruction {

struct IslandPlacementParams {
  // The measuring volume: the depth range (z) of the calibration's target
  // and screen views, widened by this much each way, mm >= 0.
  double volume_margin_mm = 60.0;
  // Junctions of the island that must lie inside it, (0, 1].
  double min_inside = 0.95;
  // Junctions an island needs, >= 3; line 0's component needs as many
  // placed on the slide to fix its own rows.
  int min_junctions = 12;
  // The shift chosen: the RMS of its junctions' slide rows about whole rows
  // (the worst tenth left out), rows, > 0;
  double max_rms_rows = 0.12;
  // every other candidate in the volume at least this many times as far
  // off, >= 1,
  double min_rival_ratio = 3.0;
  // and at least this far, rows, > 0.
  double min_rival_rms_rows = 0.15;
  // Under the shift chosen, a junction farther than this from its row is
  // ruled out (a wrong label inside the island), rows, > 0.
  double max_junction_rows = 0.2;

  // True when the numbers are usable; otherwise names the field.
  bool IsValid(std::string* error) const;
};

// The geometry of `calibration` for the decoder, or nullptr where the
// calibration has no projector matrix (its manifest had no reference views).
// std::invalid_argument for invalid params.
std::shared_ptr<const decoder::LabelGeometry> LabelGeometryOfCalibration(
    const calibration::SideCalibration& calibration, const IslandPlacementParams& params = {});

}  // namespace bsls::reconstruction

#endif  // BSLS_RECONSTRUCTION_ISLAND_PLACEMENT_H_
