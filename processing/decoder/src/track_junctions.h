// Private to bsls::decoder: the track chain's junctions as they leave it
// (thesis 5.2): one per label, placed where the line's centres meet the
// segment's (junction_placement.h), and the unlabelled ones listed.
#ifndef BSLS_DECODER_SRC_TRACK_JUNCTIONS_H_
#define BSLS_DECODER_SRC_TRACK_JUNCTIONS_H_

#include <opencv2/core.hpp>
#include <vector>

#include "bsls/decoder/decoder.h"
#include "bsls/interpretation/ridge_tracks.h"
#include "bsls/interpretation/track_labelling.h"
#include "track_centres.h"
#include "working_resolution.h"

namespace bsls::decoder::internal {

// Orders unlabelled junctions by y, as DecodeResult::unlabelled is.
void SortByRow(std::vector<UnlabelledJunction>* junctions);

// Junctions seen whose label could not be proven: reported at their ridge
// points (full frame), not placed, ordered by y.
std::vector<UnlabelledJunction> UnlabelledJunctions(const interpretation::TrackNetwork& net,
                                                    const interpretation::TrackLabels& labels,
                                                    const WorkingScale& scale);

// The labelled junctions of the network, one per label (JunctionPerLabel),
// placed (thesis 5.2) in the full frame: planned with their segments'
// columns measured, then placed, each step in parallel.
std::vector<DecodedJunction> PlaceTrackJunctions(const cv::Mat& working,
                                                 const interpretation::TrackNetwork& net,
                                                 const interpretation::TrackLabels& labels,
                                                 const std::vector<TrackCentres>& centres,
                                                 const DecodeParams& params,
                                                 const WorkingScale& scale, int* conflicts);

}  // namespace bsls::decoder::internal

#endif  // BSLS_DECODER_SRC_TRACK_JUNCTIONS_H_
