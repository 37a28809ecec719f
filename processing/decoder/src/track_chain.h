// Private to bsls::decoder: the track chain (DecodeChain::kTracks,
// docs/decoding.md "The track chain"). Ridge points along the rows and the
// columns of the smoothed frame, linked into line and segment tracks
// (interpretation/ridge_tracks.h), labelled (interpretation/
// track_labelling.h), then sub-pixel centres along every labelled line and
// junctions placed where a line's centres meet its segment's.
#ifndef BSLS_DECODER_SRC_TRACK_CHAIN_H_
#define BSLS_DECODER_SRC_TRACK_CHAIN_H_

#include <opencv2/core.hpp>

#include "bsls/decoder/decoder.h"

namespace bsls::decoder::internal {

// Decodes the CV_8UC1 frame `grey` (already checked: not blank, not
// saturated) by the track chain into `result`, whose frame fields (side,
// size, q_absolute) the caller has set. Without a reference line, result->ok
// stays false with the reason. Throws Cancelled when `cancel` asks to stop.
void DecodeByTracks(const cv::Mat& grey, pattern::Side side, const DecodeParams& params,
                    const Cancellation& cancel, DecodeResult* result);

}  // namespace bsls::decoder::internal

#endif  // BSLS_DECODER_SRC_TRACK_CHAIN_H_
