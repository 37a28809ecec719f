// Private to bsls::decoder: the track chain's labels judged by a
// calibration's geometry (issue 25 parts 3-4; docs/decoding.md, "Islands
// placed by the geometry"): line 0's component confirmed or moved, islands
// placed, and the junctions the geometry rules out listed unlabelled.
#ifndef BSLS_DECODER_SRC_TRACK_GEOMETRY_H_
#define BSLS_DECODER_SRC_TRACK_GEOMETRY_H_

#include "bsls/decoder/decoder.h"
#include "bsls/decoder/label_geometry.h"
#include "bsls/interpretation/ridge_tracks.h"
#include "bsls/interpretation/track_labelling.h"
#include "working_resolution.h"

namespace bsls::decoder::internal {

// Labels with a calibration: line 0's chain of candidates nearest the
// centre row (thesis 5.2.1), its component judged by the geometry
// (PlaceByGeometry). Where that fails, the other chains are tried in turn
// (track_chain.reference_tries), each kept only where the geometry confirms
// its labels where they stand: a line whose inner neighbours are hidden
// looks like line 0 in the image, but not in depth. The first chain's
// failure is the one reported.
interpretation::TrackLabels LabelWithGeometry(const interpretation::TrackNetwork& net,
                                              pattern::Side side, const DecodeParams& params,
                                              const WorkingScale& scale,
                                              const LabelGeometry& geometry,
                                              const Cancellation& cancel, DecodeResult* result);

// The junctions as they leave the decoder, at their sub-pixel places: a
// label the geometry rules out there is taken back and the junction listed
// unlabelled (its place can differ from the track junction's judged before).
void RuleOutPlaced(const LabelGeometry& geometry, DecodeResult* result);

}  // namespace bsls::decoder::internal

#endif  // BSLS_DECODER_SRC_TRACK_GEOMETRY_H_
