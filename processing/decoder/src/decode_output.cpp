#include "bsls/decoder/decode_output.h"

#include <cmath>
#include <opencv2/imgproc.hpp>
#include <string>

namespace bsls::decoder {
namespace {

// Rounds to 1/1000 px so the JSON stays readable.
double Round3(double v) { return std::round(v * 1000.0) / 1000.0; }

}  // namespace

nlohmann::json ToJson(const DecodeResult& r) {
  nlohmann::json j;
  j["side"] = std::string(pattern::ToString(r.side));
  j["width"] = r.width;
  j["height"] = r.height;
  j["q_origin"] = r.q_absolute ? "slide" : "relative";
  nlohmann::json junctions = nlohmann::json::array();
  for (const DecodedJunction& d : r.junctions) {
    nlohmann::json e = {{"x", Round3(d.position.x)},
                        {"y", Round3(d.position.y)},
                        {"p", d.p},
                        {"q", d.q},
                        {"kind", std::string(pattern::ToString(d.kind))}};
    if (d.interpolated) e["interpolated"] = true;
    junctions.push_back(std::move(e));
  }
  j["junctions"] = std::move(junctions);
  nlohmann::json unlabelled = nlohmann::json::array();
  for (const UnlabelledJunction& u : r.unlabelled)
    unlabelled.push_back({{"x", Round3(u.position.x)},
                          {"y", Round3(u.position.y)},
                          {"kind", std::string(pattern::ToString(u.kind))}});
  j["unlabelled"] = std::move(unlabelled);
  nlohmann::json lines = nlohmann::json::array();
  for (const DecodedLine& l : r.lines) {
    nlohmann::json points = nlohmann::json::array();
    for (const cv::Point2d& p : l.points) points.push_back({Round3(p.x), Round3(p.y)});
    lines.push_back({{"p", l.p}, {"points", std::move(points)}});
  }
  j["lines"] = std::move(lines);
  return j;
}

cv::Scalar LineColour(int p) {
  if (p == 0) return {255, 255, 255};
  // Hues spaced by the golden angle so neighbouring lines differ clearly.
  const int hue = static_cast<int>(std::fmod(p * 137.508, 180.0));
  cv::Mat hsv(1, 1, CV_8UC3, cv::Scalar(hue, 230, 255)), bgr;
  cv::cvtColor(hsv, bgr, cv::COLOR_HSV2BGR);
  const cv::Vec3b c = bgr.at<cv::Vec3b>(0, 0);
  return {static_cast<double>(c[0]), static_cast<double>(c[1]), static_cast<double>(c[2])};
}

cv::Mat RenderOverlay(const cv::Mat& grey, const DecodeResult& r) {
  cv::Mat out;
  cv::Mat dim;
  grey.convertTo(dim, CV_8U, 0.6);
  cv::cvtColor(dim, out, cv::COLOR_GRAY2BGR);
  constexpr int kShift = 4;  // fixed-point sub-pixel drawing
  constexpr double kScale = 1 << kShift;
  auto fixed = [](cv::Point2d p) {
    return cv::Point(cvRound(p.x * kScale), cvRound(p.y * kScale));
  };
  for (const DecodedLine& l : r.lines) {
    const cv::Scalar colour = LineColour(l.p);
    for (size_t i = 1; i < l.points.size(); ++i)
      if (l.points[i].y - l.points[i - 1].y <= 1.5)
        cv::line(out, fixed(l.points[i - 1]), fixed(l.points[i]), colour, 1, cv::LINE_AA, kShift);
    if (!l.points.empty()) {
      const cv::Point2d top = l.points.front();
      cv::putText(out, std::to_string(l.p),
                  cv::Point(cvRound(top.x) - 4, std::max(10, cvRound(top.y) - 4)),
                  cv::FONT_HERSHEY_PLAIN, 0.8, colour, 1, cv::LINE_AA);
    }
  }
  for (const DecodedJunction& d : r.junctions) {
    const cv::Scalar colour = LineColour(d.p);
    const cv::Point c = fixed(d.position);
    if (d.interpolated) {
      const int k = static_cast<int>(2 * kScale);
      cv::line(out, c - cv::Point(k, k), c + cv::Point(k, k), {0, 255, 255}, 1, cv::LINE_AA,
               kShift);
      cv::line(out, c - cv::Point(k, -k), c + cv::Point(k, -k), {0, 255, 255}, 1, cv::LINE_AA,
               kShift);
    } else if (d.kind == pattern::JunctionKind::kDirect) {
      cv::circle(out, c, static_cast<int>(1.6 * kScale), colour, cv::FILLED, cv::LINE_AA, kShift);
    } else {
      cv::circle(out, c, static_cast<int>(2.2 * kScale), colour, 1, cv::LINE_AA, kShift);
    }
  }
  // Unlabelled junctions: a red square each, so that what was seen but not
  // proven shows.
  for (const UnlabelledJunction& u : r.unlabelled) {
    const cv::Point c = fixed(u.position);
    const int k = static_cast<int>(2 * kScale);
    cv::rectangle(out, c - cv::Point(k, k), c + cv::Point(k, k), {0, 0, 255}, 1, cv::LINE_AA,
                  kShift);
  }
  return out;
}

}  // namespace bsls::decoder
