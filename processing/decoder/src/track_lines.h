// Private to bsls::decoder: the track chain's labelled lines as they leave
// it (contracts section 5): one centre per row of the full frame for each
// p, from its line tracks and the steep stretches that carry them on.
#ifndef BSLS_DECODER_SRC_TRACK_LINES_H_
#define BSLS_DECODER_SRC_TRACK_LINES_H_

#include <opencv2/core.hpp>
#include <vector>

#include "bsls/decoder/decoder.h"
#include "bsls/interpretation/ridge_tracks.h"
#include "bsls/interpretation/track_labelling.h"
#include "track_centres.h"
#include "working_resolution.h"

namespace bsls::decoder::internal {

// Lines: the centres of all tracks of one p, one per row of the working
// frame (`rows` of them; the first labelled track's where two hold one
// row), with the rows where a steep stretch carries a track of p on
// (SteepCentres), in the full frame.
std::vector<DecodedLine> DecodedLines(const cv::Mat& working,
                                      const interpretation::TrackNetwork& net,
                                      const std::vector<int>& labelled,
                                      const interpretation::TrackLabels& labels,
                                      const std::vector<TrackCentres>& centres, int rows,
                                      const WorkingScale& scale);

}  // namespace bsls::decoder::internal

#endif  // BSLS_DECODER_SRC_TRACK_LINES_H_
