// Junctions missing between two of their line's, placed from them (thesis
// 5.1.4.6): processing/decoder/src/missing_junctions.h.
#include "missing_junctions.h"

#include <gtest/gtest.h>

#include <vector>

namespace bsls::decoder::internal {
namespace {

using pattern::JunctionKind;

// Line p's centres x = x0 + slope * y on rows first..last, but for `gap`.
DecodedLine StraightLine(int p, double x0, double slope, int first, int last,
                         std::pair<int, int> gap = {1, 0}) {
  DecodedLine line{p, {}};
  for (int y = first; y <= last; ++y)
    if (y < gap.first || y > gap.second) line.points.push_back({x0 + slope * y, 1.0 * y});
  return line;
}

DecodedJunction Seen(int p, int q, double x, double y, JunctionKind kind) {
  DecodedJunction j;
  j.position = {x, y};
  j.p = p;
  j.q = q;
  j.kind = kind;
  return j;
}

TEST(MissingJunctions, OneLeftOutBetweenTwoOfItsLineIsPlacedOnTheLineAtItsRow) {
  // Line 3: q 1 and 3 are direct (q - p even), q 2 corresponding, left out.
  const std::vector<DecodedLine> lines{StraightLine(3, 100.0, 0.1, 0, 200)};
  std::vector<DecodedJunction> junctions{Seen(3, 1, 110.0, 100.0, JunctionKind::kDirect),
                                         Seen(3, 3, 112.0, 120.0, JunctionKind::kDirect)};
  std::vector<UnlabelledJunction> unlabelled{{{111.2, 110.5}, JunctionKind::kCorresponding},
                                             {{150.0, 110.0}, JunctionKind::kDirect}};
  PlaceMissingJunctions(lines, pattern::PatternSpec{}, 0, 3, 2.0, &junctions, &unlabelled);
  ASSERT_EQ(junctions.size(), 3u);
  const DecodedJunction& placed = junctions[1];  // ordered by p, then q
  EXPECT_EQ(placed.q, 2);
  EXPECT_TRUE(placed.interpolated);
  EXPECT_EQ(placed.kind, JunctionKind::kCorresponding);
  EXPECT_DOUBLE_EQ(placed.position.y, 110.0);
  EXPECT_NEAR(placed.position.x, 111.0, 1e-9);  // on the line at that row
  EXPECT_FALSE(junctions[0].interpolated);
  // The unlabelled junction seen there is that one; the other stays.
  ASSERT_EQ(unlabelled.size(), 1u);
  EXPECT_EQ(unlabelled[0].position.x, 150.0);
}

TEST(MissingJunctions, NoneWhereTheLineIsBrokenBetweenOrTooManyAreMissing) {
  const pattern::PatternSpec spec;
  std::vector<DecodedJunction> two{Seen(3, 1, 110.0, 100.0, JunctionKind::kDirect),
                                   Seen(3, 3, 112.0, 120.0, JunctionKind::kDirect)};
  std::vector<UnlabelledJunction> none;
  // A gap of 6 rows where a pattern row spans 10: something hides the line.
  auto junctions = two;
  PlaceMissingJunctions({StraightLine(3, 100.0, 0.1, 0, 200, {106, 111})}, spec, 0, 3, 2.0,
                        &junctions, &none);
  EXPECT_EQ(junctions.size(), 2u);
  // A gap of 4 rows (a junction's light) is bridged.
  junctions = two;
  PlaceMissingJunctions({StraightLine(3, 100.0, 0.1, 0, 200, {108, 111})}, spec, 0, 3, 2.0,
                        &junctions, &none);
  EXPECT_EQ(junctions.size(), 3u);
  // The line's centres stop short of the lower junction by more than half a row.
  junctions = two;
  PlaceMissingJunctions({StraightLine(3, 100.0, 0.1, 0, 112)}, spec, 0, 3, 2.0, &junctions, &none);
  EXPECT_EQ(junctions.size(), 2u);
  // Four left out (q 1 -> 6) against a run of three at most; none placed.
  junctions = {Seen(3, 1, 110.0, 100.0, JunctionKind::kDirect),
               Seen(3, 6, 115.0, 150.0, JunctionKind::kCorresponding)};
  PlaceMissingJunctions({StraightLine(3, 100.0, 0.1, 0, 200)}, spec, 0, 3, 2.0, &junctions, &none);
  EXPECT_EQ(junctions.size(), 2u);
  // No line of that p: nothing to place them on.
  junctions = two;
  PlaceMissingJunctions({StraightLine(4, 100.0, 0.1, 0, 200)}, spec, 0, 3, 2.0, &junctions, &none);
  EXPECT_EQ(junctions.size(), 2u);
}

TEST(MissingJunctions, LineZeroCarriesEveryOtherRowOnly) {
  // Line 0 has direct junctions on even rows alone: q 0 and 2 leave out
  // nothing; with an odd q offset its rows are the odd q.
  const std::vector<DecodedLine> lines{StraightLine(0, 50.0, 0.0, 0, 200)};
  std::vector<DecodedJunction> junctions{Seen(0, 0, 50.0, 100.0, JunctionKind::kDirect),
                                         Seen(0, 2, 50.0, 120.0, JunctionKind::kDirect)};
  std::vector<UnlabelledJunction> none;
  PlaceMissingJunctions(lines, pattern::PatternSpec{}, 0, 3, 2.0, &junctions, &none);
  EXPECT_EQ(junctions.size(), 2u);
  junctions = {Seen(0, 0, 50.0, 100.0, JunctionKind::kDirect),
               Seen(0, 4, 50.0, 140.0, JunctionKind::kDirect)};
  PlaceMissingJunctions(lines, pattern::PatternSpec{}, 0, 3, 2.0, &junctions, &none);
  ASSERT_EQ(junctions.size(), 3u);
  EXPECT_EQ(junctions[1].q, 2);
  EXPECT_DOUBLE_EQ(junctions[1].position.y, 120.0);
  EXPECT_EQ(junctions[1].kind, JunctionKind::kDirect);
  // max_run 0: none.
  junctions = {Seen(0, 0, 50.0, 100.0, JunctionKind::kDirect),
               Seen(0, 4, 50.0, 140.0, JunctionKind::kDirect)};
  PlaceMissingJunctions(lines, pattern::PatternSpec{}, 0, 0, 2.0, &junctions, &none);
  EXPECT_EQ(junctions.size(), 2u);
}

}  // namespace
}  // namespace bsls::decoder::internal
