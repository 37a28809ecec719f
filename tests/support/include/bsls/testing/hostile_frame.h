// A frame that keeps every stage of the decoder busy, for the tests of
// deadlines and draining: 2896 x 2896 (8 Mpx, bsls-processd's default pixel
// budget), every other row the stripes (pitch 15 px), the rows between
// noise. It decodes to nothing, after about 0.6 s on one core.
#ifndef BSLS_TESTING_HOSTILE_FRAME_H_
#define BSLS_TESTING_HOSTILE_FRAME_H_

#include <cmath>
#include <opencv2/core.hpp>

namespace bsls::testing {

inline cv::Mat HostileFrame() {
  cv::Mat grey(2896, 2896, CV_8UC1);
  cv::RNG rng(7);
  rng.fill(grey, cv::RNG::UNIFORM, 0, 256);
  for (int y = 0; y < grey.rows; y += 2)
    for (int x = 0; x < grey.cols; ++x)
      grey.at<uchar>(y, x) = cv::saturate_cast<uchar>(128 + 100 * std::cos(2 * CV_PI * x / 15));
  return grey;
}

}  // namespace bsls::testing

#endif  // BSLS_TESTING_HOSTILE_FRAME_H_
