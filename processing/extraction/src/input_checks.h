// Input validation shared by the extraction stages (not installed).
//
// Invalid input is the caller's error, not ours: every public function of
// bsls::extraction checks its arguments with these helpers and throws
// std::invalid_argument with a message "<Function>: <reason>".
#ifndef BSLS_EXTRACTION_SRC_INPUT_CHECKS_H_
#define BSLS_EXTRACTION_SRC_INPUT_CHECKS_H_

#include <opencv2/core.hpp>
#include <stdexcept>
#include <string>

namespace bsls::extraction::internal {

// Throws unless `image` is a non-empty CV_8UC1 matrix.
inline void RequireGrey8(const cv::Mat& image, const char* function, const char* what = "image") {
  if (image.empty()) throw std::invalid_argument(std::string(function) + ": " + what + " is empty");
  if (image.type() != CV_8UC1)
    throw std::invalid_argument(std::string(function) + ": " + what + " must be CV_8UC1, got " +
                                cv::typeToString(image.type()));
}

// Throws unless `image` is a non-empty single-channel 8U, 16U, 16S or 32F matrix.
inline void RequireScalarImage(const cv::Mat& image, const char* function) {
  if (image.empty()) throw std::invalid_argument(std::string(function) + ": image is empty");
  const int depth = image.depth();
  if (image.channels() != 1 ||
      (depth != CV_8U && depth != CV_16U && depth != CV_16S && depth != CV_32F))
    throw std::invalid_argument(std::string(function) +
                                ": image must be single-channel 8U, 16U, 16S or 32F, got " +
                                cv::typeToString(image.type()));
}

// Throws unless params.IsValid() holds, quoting its reason.
template <typename Params>
void RequireValid(const Params& params, const char* function) {
  std::string why;
  if (!params.IsValid(&why))
    throw std::invalid_argument(std::string(function) + ": invalid parameters: " + why);
}

}  // namespace bsls::extraction::internal

#endif  // BSLS_EXTRACTION_SRC_INPUT_CHECKS_H_
