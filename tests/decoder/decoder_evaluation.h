// The decoder's tests' yardstick: a face or object rendered by the simulator
// with sensor noise, and the decoded junctions and line centres scored
// against its ground truth.
#pragma once

#include <gtest/gtest.h>

#include <cstdint>
#include <vector>

#include "bsls/decoder/decoder.h"
#include "bsls/simulator/evaluation.h"
#include "bsls/simulator/renderer.h"
#include "bsls/simulator/scene.h"

namespace bsls::decoder::test {

using pattern::Side;
using simulator::SurfaceKind;

constexpr double kMatchReach = 2.5;  // px between a decoded and a true junction
constexpr double kNoiseSigma = 3.0;  // grey levels
// Junctions this close to the image border have their line cut off by it
// within a few pixels; they are scored separately.
constexpr double kBorderMargin = 10.0;  // px

// A thesis scene of `kind` seen from `side`, rendered with noise `seed`.
inline simulator::Frame RenderFrame(SurfaceKind kind, Side side, std::uint32_t seed) {
  // The default options find the bundled face in the source tree.
  const simulator::ThesisSceneOptions options;
  simulator::RenderParams params;
  params.noise_sigma = kNoiseSigma;
  params.seed = seed;
  return simulator::Render(simulator::ThesisScene(side, kind, options), params);
}

struct Evaluation {
  simulator::LabelScore inner;  // junctions clear of the image border
  simulator::LabelScore all;    // every lit and visible junction
  double line_rms = 0.0;        // px, decoded line points against the true crossings
  int line_points = 0;
};

// How well `r` labels and centres what `frame` shows.
inline Evaluation Evaluate(const simulator::Frame& frame, const DecodeResult& r) {
  const std::vector<simulator::PointLabel> truth_all = simulator::VisibleJunctions(frame.truth);
  std::vector<simulator::PointLabel> truth_inner, decoded;
  const double w = frame.image.cols, h = frame.image.rows;
  for (const simulator::PointLabel& l : truth_all)
    if (l.position.x >= kBorderMargin && l.position.y >= kBorderMargin &&
        l.position.x <= w - 1 - kBorderMargin && l.position.y <= h - 1 - kBorderMargin)
      truth_inner.push_back(l);
  for (const auto& j : r.junctions) decoded.push_back({j.p, j.q, j.position});
  Evaluation e;
  e.all = simulator::ScoreLabels(truth_all, decoded, kMatchReach);
  e.inner = simulator::ScoreLabels(truth_inner, decoded, kMatchReach);
  std::vector<simulator::LinePoints> decoded_lines;
  for (const DecodedLine& line : r.lines) decoded_lines.push_back({line.p, line.points});
  const simulator::LineScore lines =
      simulator::ScoreLines(simulator::TruthLines(frame.truth), decoded_lines);
  e.line_rms = lines.rms;
  e.line_points = lines.points;
  return e;
}

// Expects `b` to hold the junctions of `a`: the same labels at the same
// positions, to the last bit (a fatal failure when their counts differ;
// callers wrap it in ASSERT_NO_FATAL_FAILURE).
inline void ExpectSameJunctions(const DecodeResult& a, const DecodeResult& b) {
  ASSERT_EQ(a.junctions.size(), b.junctions.size());
  for (size_t i = 0; i < a.junctions.size(); ++i) {
    EXPECT_EQ(a.junctions[i].p, b.junctions[i].p);
    EXPECT_EQ(a.junctions[i].q, b.junctions[i].q);
    EXPECT_EQ(a.junctions[i].position, b.junctions[i].position);
  }
}

}  // namespace bsls::decoder::test
