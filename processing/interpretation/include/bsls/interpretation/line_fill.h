// Line filling of thesis 5.2.2: seals a gap between two pixels with
// Bresenham's integer line (Figure 5.10-5.11).
#ifndef BSLS_INTERPRETATION_LINE_FILL_H_
#define BSLS_INTERPRETATION_LINE_FILL_H_

#include <opencv2/core.hpp>
#include <vector>

namespace bsls::interpretation {

// The 8-connected Bresenham pixels from a to b, both included, with the
// independent variable chosen by the larger of |dx| and |dy|.
std::vector<cv::Point> BresenhamLine(cv::Point a, cv::Point b);

// Sets the Bresenham pixels from a to b in a CV_8UC1 image to 255, clipped to
// the image; returns how many pixels changed.
int FillGap(cv::Mat& skeleton, cv::Point a, cv::Point b);

}  // namespace bsls::interpretation

#endif  // BSLS_INTERPRETATION_LINE_FILL_H_
