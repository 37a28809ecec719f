// Private to bsls::decoder: junctions missing between two labelled ones of
// their line, placed from them (thesis 5.1.4.6), on the decoder's output.
#ifndef BSLS_DECODER_SRC_MISSING_JUNCTIONS_H_
#define BSLS_DECODER_SRC_MISSING_JUNCTIONS_H_

#include <vector>

#include "bsls/decoder/decoder.h"
#include "bsls/pattern/brick_pattern.h"

namespace bsls::decoder::internal {

// Thesis 5.1.4.6: between two consecutive labelled junctions of line p whose
// q leave out at most `max_run` junctions of the pattern, where `lines`
// holds p's centres from one to the other with no run of rows longer than
// half a pattern row without one (nothing hides the line there), each
// junction left out is placed on that line at the row its q gives between
// the two, its kind the pattern's
// (q - q_offset is the slide row up to an even offset), flagged
// interpolated. An unlabelled junction within `same_px` of one placed is
// that junction seen: it leaves the unlabelled list. `junctions` are left
// ordered by p, then q; max_run <= 0 places none.
void PlaceMissingJunctions(const std::vector<DecodedLine>& lines, const pattern::PatternSpec& spec,
                           int q_offset, int max_run, double same_px,
                           std::vector<DecodedJunction>* junctions,
                           std::vector<UnlabelledJunction>* unlabelled);

}  // namespace bsls::decoder::internal

#endif  // BSLS_DECODER_SRC_MISSING_JUNCTIONS_H_
