// The decoder's outputs as files a person or a tool can open: the labelled
// junctions and lines as JSON (contracts section 5) and an overlay image that
// colours every line by its p (thesis 5.1.4.9).
#ifndef BSLS_DECODER_DECODE_OUTPUT_H_
#define BSLS_DECODER_DECODE_OUTPUT_H_

#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>

#include "bsls/decoder/decoder.h"

namespace bsls::decoder {

// Contracts section 5 JSON: side, width, height, junctions {x, y, p, q, kind}
// and lines {p, points}. Keys beyond the contract, which readers may
// ignore: "q_origin" ("relative" or "slide"); on junctions placed from
// their neighbours rather than seen, "interpolated": true; "unlabelled":
// the junctions seen whose label could not be proven, {x, y, kind}.
nlohmann::json ToJson(const DecodeResult& result);

// A BGR picture of the frame with each labelled line drawn in a colour of its
// own p (the reference line white), direct junctions as filled dots,
// corresponding ones as rings, interpolated ones as crosses, unlabelled ones
// as red squares, and p written at the top of each line.
cv::Mat RenderOverlay(const cv::Mat& grey, const DecodeResult& result);

// The colour (BGR) the overlay gives line p.
cv::Scalar LineColour(int p);

}  // namespace bsls::decoder

#endif  // BSLS_DECODER_DECODE_OUTPUT_H_
