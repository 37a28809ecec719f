#include "bsls/interpretation/chain_code.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <stdexcept>
#include <string>

namespace bsls::interpretation {

std::string_view ToString(EndDirection ed) {
  switch (ed) {
    case EndDirection::kTop:
      return "TEP";
    case EndDirection::kBottom:
      return "BEP";
    case EndDirection::kRight:
      return "REP";
    case EndDirection::kLeft:
      return "LEP";
  }
  return "?";
}

int DirectionCode(int dx, int dy) {
  // The codes by (dy + 1) * 3 + dx + 1 (rows up, level, down), from kCodeDx / kCodeDy.
  static constexpr std::array<int, 9> kByStep = [] {
    std::array<int, 9> t{-1, -1, -1, -1, -1, -1, -1, -1, -1};
    for (int c = 0; c < 8; ++c) t[static_cast<size_t>((kCodeDy[c] + 1) * 3 + kCodeDx[c] + 1)] = c;
    return t;
  }();
  if (dx < -1 || dx > 1 || dy < -1 || dy > 1) return -1;
  return kByStep[static_cast<size_t>((dy + 1) * 3 + dx + 1)];
}

double LeanFromVerticalDeg(cv::Point2d d) {
  return std::atan2(std::abs(d.x), std::abs(d.y)) * 180.0 / 3.14159265358979323846;
}

double AngleBetweenDeg(cv::Point2d a, cv::Point2d b) {
  const double norms = std::hypot(a.x, a.y) * std::hypot(b.x, b.y);
  if (norms <= 0.0) return 0.0;
  const double c = (a.x * b.x + a.y * b.y) / norms;
  return std::acos(std::clamp(c, -1.0, 1.0)) * 180.0 / 3.14159265358979323846;
}

int DifferenceCode(int code, int next_code) {
  const int diff = next_code - code;
  if (std::abs(diff) < 4) return diff;
  if (diff > 4) return diff - 8;
  if (diff < -4) return diff + 8;
  return 4;  // |diff| == 4: a reversal
}

std::vector<int> ChainCodes(const std::vector<cv::Point>& path) {
  std::vector<int> codes;
  if (path.size() < 2) return codes;
  codes.reserve(path.size() - 1);
  for (size_t i = 1; i < path.size(); ++i) {
    const int c = DirectionCode(path[i].x - path[i - 1].x, path[i].y - path[i - 1].y);
    if (c < 0)
      throw std::invalid_argument("ChainCodes: pixels " + std::to_string(i - 1) + " and " +
                                  std::to_string(i) + " of the path are not 8-neighbours");
    codes.push_back(c);
  }
  return codes;
}

std::vector<int> DifferenceCodes(const std::vector<int>& codes) {
  std::vector<int> diffs;
  if (codes.size() < 2) return diffs;
  diffs.reserve(codes.size() - 1);
  for (size_t i = 1; i < codes.size(); ++i) diffs.push_back(DifferenceCode(codes[i - 1], codes[i]));
  return diffs;
}

EndDirection ClassifyEnd(double dx, double dy) {
  if (std::abs(dy) >= std::abs(dx)) return dy > 0 ? EndDirection::kTop : EndDirection::kBottom;
  return dx < 0 ? EndDirection::kRight : EndDirection::kLeft;
}

std::optional<EndDirection> ClassifyEndByCodes(int previous, int current, int next) {
  // Eq. 5.5: a reversal either directly (c_i, c_{i+1} opposite) or through one
  // diagonal turn pixel (c_{i-1}, c_i, c_{i+1}).
  auto is = [](int a, int b) { return (a & 7) == b; };
  if ((is(current, 2) && is(next, 6)) || (is(previous, 2) && is(current, 1) && is(next, 5)) ||
      (is(previous, 2) && is(current, 3) && is(next, 7)))
    return EndDirection::kTop;
  if ((is(current, 6) && is(next, 2)) || (is(previous, 6) && is(current, 5) && is(next, 1)) ||
      (is(previous, 6) && is(current, 7) && is(next, 3)))
    return EndDirection::kBottom;
  if ((is(current, 0) && is(next, 4)) || (is(previous, 0) && is(current, 1) && is(next, 5)) ||
      (is(previous, 0) && is(current, 7) && is(next, 3)))
    return EndDirection::kRight;
  if ((is(current, 4) && is(next, 0)) || (is(previous, 4) && is(current, 5) && is(next, 1)) ||
      (is(previous, 4) && is(current, 3) && is(next, 7)))
    return EndDirection::kLeft;
  return std::nullopt;
}

}  // namespace bsls::interpretation
