// Labels proven by agreement over the junction graph (label_consensus.h):
// small graphs whose true labels are known, joined by links right and wrong.
#include "label_consensus.h"

#include <gtest/gtest.h>

#include <climits>
#include <utility>
#include <vector>

namespace bsls::interpretation::internal {
namespace {

constexpr int kNone = INT_MIN;

// A graph built from true labels: junction j is (p, v); a link's change is
// the difference of its ends' labels unless told otherwise.
struct Graph {
  std::vector<std::pair<int, int>> truth;
  std::vector<ConsensusLink> links;

  int Add(int p, int v) {
    truth.emplace_back(p, v);
    return static_cast<int>(truth.size()) - 1;
  }
  void Link(int a, int b, bool trusted, bool smooth = false) {
    links.push_back({a, b, truth[b].first - truth[a].first, truth[b].second - truth[a].second,
                     trusted, smooth});
  }
  // A step across a break in a line whose rows were counted over the gap,
  // off by dv rows from the truth.
  void GapLink(int a, int b, int dv = 0) {
    links.push_back({a, b, truth[b].first - truth[a].first, truth[b].second - truth[a].second + dv,
                     false, false, false, true});
  }
  // A link whose change is off by (dp, dv) from the truth: a wrong one.
  void WrongLink(int a, int b, int dp, int dv, bool trusted = false) {
    links.push_back({a, b, truth[b].first - truth[a].first + dp,
                     truth[b].second - truth[a].second + dv, trusted, false});
  }
  std::vector<char> OddKind() const {
    std::vector<char> odd;
    for (const auto& [p, v] : truth) odd.push_back(((p + v) % 2 + 2) % 2);
    return odd;
  }
};

// Patch A: lines 0 and 1, rows 0-3, closed by trusted links; its two seeds
// on line 0. Patch B: line 2, rows 1-3. Nothing joins them yet.
struct TwoPatches : ::testing::Test {
  void SetUp() override {
    a0 = g.Add(0, 0);
    a1 = g.Add(0, 2);
    a2 = g.Add(1, 0);
    a3 = g.Add(1, 1);
    a4 = g.Add(1, 2);
    a5 = g.Add(1, 3);
    g.Link(a0, a1, true);
    g.Link(a0, a2, true);
    g.Link(a2, a3, true);
    g.Link(a3, a4, true);
    g.Link(a1, a4, true);
    g.Link(a4, a5, true);
    b0 = g.Add(2, 1);
    b1 = g.Add(2, 2);
    b2 = g.Add(2, 3);
    g.Link(b0, b1, true);
    g.Link(b1, b2, true);
  }
  // The consensus with `seeds` on line 0 (default: patch A's two).
  Consensus Run(std::vector<int> seeds = {}) const {
    if (seeds.empty()) seeds = {a0, a1};
    return LabelByConsensus(g.OddKind(), g.links, seeds, 2, ConsensusParams{});
  }
  // Expects junction j labelled with its true p and with v true up to the
  // even offset of the whole frame, taken from a0.
  void ExpectRight(const Consensus& c, int j) const {
    ASSERT_NE(c.p[j], kNone) << "junction " << j;
    EXPECT_EQ(c.p[j], g.truth[j].first) << "junction " << j;
    EXPECT_EQ(c.v[j] - c.v[a0], g.truth[j].second - g.truth[a0].second) << "junction " << j;
  }

  Graph g;
  int a0, a1, a2, a3, a4, a5, b0, b1, b2;
};

TEST_F(TwoPatches, LineZerosPatchIsLabelledAndTheOtherIsNotGuessed) {
  g.Link(a3, b0, false);  // one segment: not proof
  const Consensus c = Run();
  for (int j : {a0, a1, a2, a3, a4, a5}) ExpectRight(c, j);
  for (int j : {b0, b1, b2}) EXPECT_EQ(c.p[j], kNone) << "junction " << j;
}

TEST_F(TwoPatches, TwoAgreeingLinksJoinThem) {
  g.Link(a3, b0, false);
  g.Link(a5, b2, false);
  const Consensus c = Run();
  for (int j : {a0, a1, a2, a3, a4, a5, b0, b1, b2}) ExpectRight(c, j);
}

// Steps across gaps alone do not join two patches, however many agree:
// where an occluding edge cuts the lines of the surface behind it (the base
// plane below a cylinder, held-out seed 101010), those lines end on the edge
// and lines of the surface in front go on from there, and the steps bridging
// them agree on a join lines off. One whole link among them is enough.
TEST_F(TwoPatches, StepsAcrossGapsAloneDoNotJoinThem) {
  g.GapLink(a3, b0);
  g.GapLink(a4, b1);
  g.GapLink(a5, b2);
  g.GapLink(a2, b0, 0);
  const Consensus c = Run();
  for (int j : {a0, a1, a2, a3, a4, a5}) ExpectRight(c, j);
  for (int j : {b0, b1, b2}) EXPECT_EQ(c.p[j], kNone) << "junction " << j;

  ConsensusParams any_links;  // the rule before: four half votes of any kind
  any_links.min_whole_links = 0;
  const Consensus before = LabelByConsensus(g.OddKind(), g.links, {a0, a1}, 2, any_links);
  for (int j : {b0, b1, b2}) ExpectRight(before, j);

  g.Link(a5, b2, false);  // one whole link
  const Consensus whole = Run();
  for (int j : {b0, b1, b2}) ExpectRight(whole, j);
}

TEST_F(TwoPatches, ALinkGivingAnotherShiftKeepsThemApart) {
  g.Link(a3, b0, false);
  g.Link(a5, b2, false);
  g.WrongLink(a4, b1, 2, 0);  // as across an occluding edge: two lines off
  const Consensus c = Run();
  for (int j : {b0, b1, b2}) EXPECT_EQ(c.p[j], kNone) << "junction " << j;
}

TEST_F(TwoPatches, TwoLinksAgreeingOnAnImpossibleShiftJoinNothing) {
  // One line and one row off: p + v changes parity, which no true shift does.
  g.WrongLink(a3, b0, 1, 0);
  g.WrongLink(a5, b2, 1, 0);
  const Consensus c = Run();
  for (int j : {b0, b1, b2}) EXPECT_EQ(c.p[j], kNone) << "junction " << j;
}

TEST_F(TwoPatches, AContradictedClosedBrickLinkLeavesNoWrongLabel) {
  g.WrongLink(a2, a5, 0, 2, /*trusted=*/true);
  const Consensus c = Run();
  EXPECT_GE(c.contradicted_links, 1);
  for (size_t j = 0; j < g.truth.size(); ++j)
    if (c.p[j] != kNone) ExpectRight(c, static_cast<int>(j));
}

TEST_F(TwoPatches, ALoneJunctionJoinsThroughTwoAgreeingLinks) {
  const int lone = g.Add(1, 4);
  g.Link(a5, lone, false);
  Consensus c = Run();
  EXPECT_EQ(c.p[lone], kNone);     // one plain link: not proof
  const int beside = g.Add(0, 4);  // a lone neighbour whose own link agrees
  g.Link(a1, beside, false);
  g.Link(beside, lone, false);
  c = Run();
  ExpectRight(c, lone);
  ExpectRight(c, beside);
}

TEST_F(TwoPatches, ALoneJunctionJoinsThroughOneSmoothStep) {
  const int lone = g.Add(1, 4);
  g.Link(a5, lone, false, /*smooth=*/true);
  ExpectRight(Run(), lone);
}

TEST_F(TwoPatches, ASmoothStepThatAnotherLinkContradictsProvesNothing) {
  const int lone = g.Add(1, 4);
  g.Link(a5, lone, false, /*smooth=*/true);
  g.WrongLink(a1, lone, 2, 0);
  EXPECT_EQ(Run().p[lone], kNone);
}

TEST_F(TwoPatches, SeedsThatDisagreeAreRefused) {
  // Two more seeds in patch B, which two links join: their p is 2, not 0.
  g.Link(a3, b0, false);
  g.Link(a5, b2, false);
  EXPECT_NE(Run().p[a0], kNone);
  const Consensus c = Run({a0, a1, b0, b1});
  for (size_t j = 0; j < g.truth.size(); ++j) EXPECT_EQ(c.p[j], kNone) << "junction " << j;
}

}  // namespace
}  // namespace bsls::interpretation::internal

namespace bsls::interpretation::internal {
namespace {

// Line 0 broken in two (the nose's tip): patch C holds line 0's lower
// junctions, which are seeds too, and one link crosses the gap.
struct BrokenLineZero : TwoPatches {
  void SetUp() override {
    TwoPatches::SetUp();
    c0 = g.Add(0, 6);
    c1 = g.Add(0, 8);
    c2 = g.Add(1, 6);
    g.Link(c0, c1, true);
    g.Link(c0, c2, true);
  }
  int c0, c1, c2;
};

TEST_F(BrokenLineZero, ItsPartsJoinThroughALinkTheirSeedsConfirm) {
  g.Link(a1, c0, false);  // the row count across the gap
  const Consensus c = Run({a0, a1, c0, c1});
  for (int j : {a0, a1, a2, c0, c1, c2}) ExpectRight(c, j);
}

TEST_F(BrokenLineZero, OneRowCountAcrossAGapDoesNotFixItsRows) {
  // The seeds confirm p, not v: a single count over a gap (which an
  // occluding edge shifts by whole rows) is half a vote, and no join.
  g.GapLink(a1, c0, 2);
  const Consensus c = Run({a0, a1, c0, c1});
  for (int j : {a0, a1, a2}) ExpectRight(c, j);
  for (int j : {c0, c1, c2}) EXPECT_EQ(c.p[j], kNone) << "junction " << j;
}

TEST_F(BrokenLineZero, OneRowCountJoinsWhereTheRowsAreCheckedAfter) {
  // With a calibration the geometry checks every junction's row, and the
  // decoder asks for one half vote.
  g.GapLink(a1, c0);
  ConsensusParams params;
  params.min_seeded_half_votes = 1;
  const Consensus c = LabelByConsensus(g.OddKind(), g.links, {a0, a1, c0, c1}, 2, params);
  for (int j : {a0, a1, a2, c0, c1, c2}) ExpectRight(c, j);
}

TEST_F(BrokenLineZero, TwoRowCountsAcrossGapsThatAgreeJoinIt) {
  g.GapLink(a1, c0);
  g.GapLink(a4, c2);
  const Consensus c = Run({a0, a1, c0, c1});
  for (int j : {a0, a1, a2, c0, c1, c2}) ExpectRight(c, j);
}

TEST_F(BrokenLineZero, APartJoinedOnlyThroughAnotherPartJoinsToo) {
  // Line 0 in three parts: D joins A through a link its seeds confirm, and
  // C joins D alone (C's junctions come first, so C is asked before D is
  // joined).
  const int d0 = g.Add(0, 10), d1 = g.Add(0, 12), d2 = g.Add(1, 10);
  g.Link(d0, d1, true);
  g.Link(d0, d2, true);
  g.Link(a1, d0, false);
  g.Link(c1, d0, false);
  const Consensus c = Run({a0, a1, c0, c1, d0, d1});
  for (int j : {a0, a1, a2, c0, c1, c2, d0, d1, d2}) ExpectRight(c, j);
}

TEST_F(BrokenLineZero, ALinkTheSeedsContradictJoinsNothing) {
  g.WrongLink(a3, c2, 2, 0);  // would put C's line 0 at p = 2
  const Consensus c = Run({a0, a1, c0, c1});
  for (int j : {a0, a1, a2}) ExpectRight(c, j);
  for (int j : {c0, c1, c2}) EXPECT_EQ(c.p[j], kNone) << "junction " << j;
}

// Islands: a part not joined to line 0's, proven in itself, comes back
// labelled relative to itself (for a calibration to place), not labelled.
TEST_F(TwoPatches, APartNotJoinedIsAnIslandRightUpToOneShift) {
  ConsensusParams params;
  params.min_island = 3;
  const Consensus c = LabelByConsensus(g.OddKind(), g.links, {a0, a1}, 2, params);
  ASSERT_EQ(c.islands, 1);
  for (int j : {a0, a1, a2, a3, a4, a5}) EXPECT_EQ(c.island[j], -1) << "junction " << j;
  for (int j : {b0, b1, b2}) {
    EXPECT_EQ(c.p[j], kNone) << "junction " << j;
    ASSERT_EQ(c.island[j], 0) << "junction " << j;
    // One shift for the whole island, keeping p + v's parity.
    EXPECT_EQ(c.island_p[j] - c.island_p[b0], g.truth[j].first - g.truth[b0].first);
    EXPECT_EQ(c.island_v[j] - c.island_v[b0], g.truth[j].second - g.truth[b0].second);
    EXPECT_EQ(((c.island_p[j] + c.island_v[j]) % 2 + 2) % 2, g.OddKind()[j]);
  }
}

TEST_F(TwoPatches, AnIslandSmallerThanTheMinimumIsNotKept) {
  ConsensusParams params;
  params.min_island = 4;  // patch B has 3 junctions
  const Consensus c = LabelByConsensus(g.OddKind(), g.links, {a0, a1}, 2, params);
  EXPECT_EQ(c.islands, 0);
  for (int j : {b0, b1, b2}) EXPECT_EQ(c.island[j], -1) << "junction " << j;
}

TEST_F(TwoPatches, APartJoinedToLineZerosIsNoIsland) {
  g.Link(a3, b0, false);
  g.Link(a5, b2, false);
  ConsensusParams params;
  params.min_island = 3;
  const Consensus c = LabelByConsensus(g.OddKind(), g.links, {a0, a1}, 2, params);
  EXPECT_EQ(c.islands, 0);
}

}  // namespace
}  // namespace bsls::interpretation::internal
