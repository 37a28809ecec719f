// Directional (chain) codes of thesis 5.2.3 (Figure 5.13, eq. 5.1-5.5) and
// their inverse of thesis 5.1.4.1 (eq. 5.9-5.11).
//
// Image coordinates: x to the right, y downwards (rows). The eight codes run
// anticlockwise as seen on the screen: 0 = +x, 2 = up (-y), 4 = -x, 6 = down.
#ifndef BSLS_INTERPRETATION_CHAIN_CODE_H_
#define BSLS_INTERPRETATION_CHAIN_CODE_H_

#include <array>
#include <opencv2/core.hpp>
#include <optional>
#include <string_view>
#include <vector>

namespace bsls::interpretation {

inline constexpr std::array<int, 8> kCodeDx = {1, 1, 0, -1, -1, -1, 0, 1};
inline constexpr std::array<int, 8> kCodeDy = {0, -1, -1, -1, 0, 1, 1, 1};

// End-point directions of eq. 5.5 with the thesis's numbering (ed).
enum class EndDirection { kTop = 0, kBottom = 1, kRight = 2, kLeft = 3 };

// "TEP", "BEP", "REP" or "LEP".
std::string_view ToString(EndDirection ed);

// The code of a unit step (dx, dy), or -1 when the step is not one of the eight.
int DirectionCode(int dx, int dy);

// The step of a code.
inline cv::Point CodeStep(int code) { return {kCodeDx[code & 7], kCodeDy[code & 7]}; }

// True when p lies inside `image` (CV_8UC1) and is non-zero there.
inline bool IsSetPixel(const cv::Mat& image, cv::Point p) {
  return p.x >= 0 && p.y >= 0 && p.x < image.cols && p.y < image.rows && image.at<uchar>(p) != 0;
}

// Degrees a direction leans from the vertical image axis (0 = straight up or down).
double LeanFromVerticalDeg(cv::Point2d direction);

// Degrees between two directions (0..180); the vectors need not be unit length.
double AngleBetweenDeg(cv::Point2d a, cv::Point2d b);

// Thesis eq. 5.4: difference code d_i of consecutive codes, in -3..4 (4 = reversal).
int DifferenceCode(int code, int next_code);

// Thesis eq. 5.9: the inverse directional code c'_i = c_i + 4 (mod 8).
inline int InverseCode(int code) { return (code + 4) & 7; }

// Chain codes of an 8-connected pixel path (size - 1 codes); throws
// std::invalid_argument when two consecutive pixels are not 8-neighbours.
std::vector<int> ChainCodes(const std::vector<cv::Point>& path);

// Difference codes of a code sequence (eq. 5.3), one per consecutive pair.
std::vector<int> DifferenceCodes(const std::vector<int>& codes);

// Thesis eq. 5.5 applied to a stub: the end-point class of a line end whose
// piece leaves the end in direction (dx, dy) (image axes). An end whose piece
// goes down is a top end point (TEP), and so on.
EndDirection ClassifyEnd(double dx, double dy);

// Thesis eq. 5.5 on three consecutive chain codes around a reversal
// (c_{i-1}, c_i, c_{i+1}); nullopt when they do not describe an end point.
std::optional<EndDirection> ClassifyEndByCodes(int previous, int current, int next);

}  // namespace bsls::interpretation

#endif  // BSLS_INTERPRETATION_CHAIN_CODE_H_
