// Labels of one decode kept only where a second decode of the same frame
// proves them (docs/decoding.md, "Surfaces: the skeleton chain's geometry,
// the track chain's labels").
//
// The skeleton chain (thesis chapters 4-5) places junctions and keeps
// steep lines better, but spreads labels from line 0 along the cheapest
// paths and so can label a region wrongly (a base plane below a ramp, a
// cavity's wall, a frame whose line 0 is hidden). The track chain labels
// only what its junction graph proves, and lists the rest unlabelled. A
// surface takes the first's geometry under the second's labels: each
// junction where the proof has the same label beside it, each line between
// such junctions. Nothing the proof does not confirm is reported labelled.
//
// Thread-safety: pure function.
#ifndef BSLS_DECODER_LABEL_PROOF_H_
#define BSLS_DECODER_LABEL_PROOF_H_

#include <string>

#include "bsls/decoder/decoder.h"

namespace bsls::decoder {

struct LabelProofParams {
  // px of the frame: a junction and the proof's beside it lie this close
  // (the two chains place one junction within about 1 px), > 0.
  double reach_px = 2.5;
  // A line runs on past its last (or before its first) proven junction for
  // at most this many row spacings with no junction between (a line's end
  // at the outline, a lump's steep skirt), >= 0.
  double tail_rows = 1.5;

  // True when the values are usable; otherwise says why.
  bool IsValid(std::string* error) const;
};

struct LabelProofReport {
  int proven = 0;     // geometry's junctions whose label the proof has beside them
  int refuted = 0;    // those beside which the proof has another label, or none proven
  int unproven = 0;   // those the proof did not see (reported unlabelled)
  int added = 0;      // the proof's labelled junctions where geometry has no proven one
  int rows_kept = 0;  // geometry's line rows between proven junctions (or in their tails)
  int rows_dropped = 0;
  int rows_added = 0;  // the proof's line rows where geometry kept none
};

// The labels `proof` (a decode of the same frame by the track chain) proves,
// with `geometry`'s junctions and line rows where they agree: geometry's
// junctions whose label the proof has beside them; geometry's line rows
// between two such junctions of the line, or within tail_rows of one at a
// line's end; and the proof's own junctions and rows where geometry kept
// none. q keeps geometry's origin (the offset between the two decodes'
// origins is the one most matched junctions give). The unlabelled list is
// the proof's, with geometry's junctions that the proof did not see. Where
// either decode refused the frame, or none of geometry's labels matches the
// proof's, the result is `proof` itself. Throws std::invalid_argument for
// invalid params.
DecodeResult KeepProvenLabels(const DecodeResult& geometry, const DecodeResult& proof,
                              const LabelProofParams& params = {},
                              LabelProofReport* report = nullptr);

}  // namespace bsls::decoder

#endif  // BSLS_DECODER_LABEL_PROOF_H_
