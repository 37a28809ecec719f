// The skeleton chain's geometry under the labels the track chain proves
// (decoder/label_proof.h): small decodes whose verdicts are known.
#include "bsls/decoder/label_proof.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <vector>

namespace bsls::decoder {
namespace {

using pattern::JunctionKind;

constexpr double kSpacing = 13.0;  // px per row along a line

// Junction of row q on line p: lines stand at x = 100 + 20 p, rows at y = 10 + 13 q.
DecodedJunction At(int p, int q) {
  return {cv::Point2d(100.0 + 20.0 * p, 10.0 + kSpacing * q), p, q,
          (p + q) % 2 == 0 ? JunctionKind::kDirect : JunctionKind::kCorresponding};
}

// Line p over rows [y0, y1], leaving out the two rows beside each junction
// of `rows` (as the skeleton chain's lines do).
DecodedLine LineOf(int p, int y0, int y1, const std::vector<int>& rows) {
  DecodedLine line{p, {}};
  for (int y = y0; y <= y1; ++y) {
    const bool beside = std::any_of(rows.begin(), rows.end(), [&](int q) {
      return std::abs(y - (10.0 + kSpacing * q)) <= 1.0;
    });
    if (!beside) line.points.emplace_back(100.0 + 20.0 * p, y);
  }
  return line;
}

DecodeResult Decoded(std::vector<DecodedJunction> junctions, std::vector<DecodedLine> lines) {
  DecodeResult r;
  r.ok = true;
  r.width = r.height = 200;
  r.junctions = std::move(junctions);
  r.lines = std::move(lines);
  return r;
}

bool HasLabel(const DecodeResult& r, int p, int q) {
  return std::any_of(r.junctions.begin(), r.junctions.end(),
                     [&](const DecodedJunction& j) { return j.p == p && j.q == q; });
}

bool HasRow(const DecodeResult& r, int p, double y) {
  for (const DecodedLine& l : r.lines)
    if (l.p == p)
      for (const cv::Point2d& c : l.points)
        if (c.y == y) return true;
  return false;
}

// The geometry decode: lines 1 and 2, rows 0-9 of each, a junction per row;
// q origins differ by 2 between the two decodes.
struct Proof : ::testing::Test {
  void SetUp() override {
    std::vector<DecodedJunction> js;
    for (int p : {1, 2})
      for (int q = 0; q < 10; ++q) js.push_back(At(p, q));
    std::vector<int> rows(10);
    for (int q = 0; q < 10; ++q) rows[q] = q;
    geometry = Decoded(js, {LineOf(1, 0, 160, rows), LineOf(2, 0, 160, rows)});
    // The proof: the same junctions at q - 2, nudged by half a pixel.
    std::vector<DecodedJunction> proven;
    for (DecodedJunction j : js) {
      j.q -= 2;
      j.position += cv::Point2d(0.5, -0.4);
      proven.push_back(j);
    }
    proof = Decoded(proven, {});
  }
  // Takes junction (p, q) of the geometry out of the proof (q in geometry's origin).
  DecodedJunction Take(int p, int q) {
    auto it = std::find_if(proof.junctions.begin(), proof.junctions.end(),
                           [&](const DecodedJunction& j) { return j.p == p && j.q == q - 2; });
    const DecodedJunction j = *it;
    proof.junctions.erase(it);
    return j;
  }
  DecodeResult geometry, proof;
};

TEST_F(Proof, EverythingTheProofConfirmsIsKeptInGeometrysOrigin) {
  LabelProofReport report;
  const DecodeResult r = KeepProvenLabels(geometry, proof, {}, &report);
  ASSERT_TRUE(r.ok);
  EXPECT_EQ(report.proven, 20);
  EXPECT_EQ(report.added, 0);
  EXPECT_EQ(r.junctions.size(), 20u);
  EXPECT_TRUE(HasLabel(r, 1, 0));
  EXPECT_TRUE(HasLabel(r, 2, 9));
  EXPECT_EQ(r.junctions.front().position, At(1, 0).position);  // geometry's place
  // Rows between junctions, and a row spacing and a half beyond the last.
  EXPECT_TRUE(HasRow(r, 1, 55));
  EXPECT_TRUE(HasRow(r, 1, 10 + 9 * kSpacing + 19));   // 1.46 row spacings on
  EXPECT_FALSE(HasRow(r, 1, 10 + 9 * kSpacing + 21));  // 1.62
  EXPECT_TRUE(r.unlabelled.empty());
}

TEST_F(Proof, ALabelTheProofGivesOtherwiseIsTheProofs) {
  // The proof says (1, 5) is (3, 5): geometry's label goes, and with it
  // line 1's rows on both sides of it; the proof's label stands there.
  DecodedJunction j = Take(1, 5);
  j.p = 3;
  proof.junctions.push_back(j);
  LabelProofReport report;
  const DecodeResult r = KeepProvenLabels(geometry, proof, {}, &report);
  EXPECT_EQ(report.refuted, 1);
  EXPECT_FALSE(HasLabel(r, 1, 5));
  EXPECT_TRUE(HasLabel(r, 3, 5));
  EXPECT_FALSE(HasRow(r, 1, 68));  // between rows 4 and 5
  EXPECT_FALSE(HasRow(r, 1, 81));  // between rows 5 and 6
  EXPECT_TRUE(HasRow(r, 1, 55));   // between rows 3 and 4
}

TEST_F(Proof, AJunctionTheProofLeftUnlabelledIsNotLabelled) {
  // The proof saw (2, 9), the last of line 2, but proved no label for it:
  // no smooth step along the line overrules that.
  const DecodedJunction j = Take(2, 9);
  proof.unlabelled.push_back({j.position, j.kind});
  const DecodeResult r = KeepProvenLabels(geometry, proof);
  EXPECT_FALSE(HasLabel(r, 2, 9));
  EXPECT_EQ(r.unlabelled.size(), 1u);
  EXPECT_FALSE(HasRow(r, 2, 10 + 8.5 * kSpacing));
}

TEST_F(Proof, AJunctionOneSmoothStepBeyondTheProofsReachIsProven) {
  // The proof did not see (1, 9) at all: one row step down its unbroken
  // line from two proven ones, it is proven. (2, 8) and (2, 9) unseen:
  // (2, 8) steps from (2, 7), then (2, 9) from (2, 8).
  Take(1, 9);
  Take(2, 8);
  Take(2, 9);
  LabelProofReport report;
  const DecodeResult r = KeepProvenLabels(geometry, proof, {}, &report);
  EXPECT_TRUE(HasLabel(r, 1, 9));
  EXPECT_TRUE(HasLabel(r, 2, 8));
  EXPECT_TRUE(HasLabel(r, 2, 9));
  EXPECT_TRUE(r.unlabelled.empty());
}

TEST_F(Proof, AStepAcrossABreakInTheLineOrOffTheRowsProvesNothing) {
  // (1, 9) unseen, and line 1 broken for 8 rows above it: not proven. (2, 9)
  // unseen and 5 px off its row: not proven either; both reported unlabelled.
  Take(1, 9);
  Take(2, 9);
  auto& line1 = geometry.lines[0].points;
  line1.erase(std::remove_if(line1.begin(), line1.end(),
                             [](const cv::Point2d& c) { return c.y > 120 && c.y < 128; }),
              line1.end());
  for (DecodedJunction& j : geometry.junctions)
    if (j.p == 2 && j.q == 9) j.position.y += 5.0;
  const DecodeResult r = KeepProvenLabels(geometry, proof);
  EXPECT_FALSE(HasLabel(r, 1, 9));
  EXPECT_FALSE(HasLabel(r, 2, 9));
  EXPECT_EQ(r.unlabelled.size(), 2u);
}

TEST_F(Proof, WhatTheProofRefusesIsRefused) {
  proof.ok = false;  // as the track chain refuses: nothing labelled
  proof.error = "no reference line (line 0): none found";
  proof.junctions.clear();
  const DecodeResult r = KeepProvenLabels(geometry, proof);
  EXPECT_FALSE(r.ok);
  EXPECT_EQ(r.error, proof.error);
  EXPECT_TRUE(r.junctions.empty());
}

TEST_F(Proof, WhereGeometryRefusesOrNothingMatchesTheProofStandsAlone) {
  DecodeResult refused = geometry;
  refused.ok = false;
  EXPECT_EQ(KeepProvenLabels(refused, proof).junctions.size(), proof.junctions.size());
  for (DecodedJunction& j : geometry.junctions) j.position.x += 50.0;  // another place entirely
  const DecodeResult r = KeepProvenLabels(geometry, proof);
  ASSERT_TRUE(r.ok);
  EXPECT_EQ(r.junctions.size(), proof.junctions.size());
  EXPECT_TRUE(HasLabel(r, 1, -2));  // the proof's own origin
}

TEST(LabelProofParams, InvalidValuesAreRejected) {
  LabelProofParams params;
  params.reach_px = 0.0;
  EXPECT_THROW(KeepProvenLabels({}, {}, params), std::invalid_argument);
  params = {};
  params.tail_rows = -1.0;
  std::string why;
  EXPECT_FALSE(params.IsValid(&why));
  EXPECT_NE(why.find("tail_rows"), std::string::npos);
}

}  // namespace
}  // namespace bsls::decoder
