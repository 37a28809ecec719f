// Islands placed by the geometry (island_placement.h): the simulator's plane
// scene, its exact junctions split into line 0's part and an island whose
// labels are shifted, under a calibration made of the scene's own devices
// (CalibrationOfKnownDevices).
#include "bsls/reconstruction/island_placement.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <map>
#include <random>
#include <string>
#include <vector>

#include "bsls/reconstruction/calibrated_model.h"
#include "bsls/simulator/ground_truth.h"
#include "bsls/simulator/scene.h"

namespace bsls::reconstruction {
namespace {

using pattern::Side;

struct PlaneRig {
  calibration::SideCalibration calibration;
  std::vector<simulator::TruthJunction> visible;
};

// The calibration of the thesis rig's `side` as a session at z = 0 and
// z = 100 mm would give it, without the measuring errors.
const PlaneRig& Rig(Side side) {
  static std::map<Side, PlaneRig> cache;
  auto it = cache.find(side);
  if (it != cache.end()) return it->second;
  const simulator::Scene scene = simulator::ThesisScene(side, simulator::SurfaceKind::kPlane);
  const simulator::GroundTruth truth = simulator::ComputeGroundTruth(scene);
  PlaneRig rig;
  rig.calibration = CalibrationOfKnownDevices(side, truth.camera, truth.projector, truth.pattern,
                                              truth.width, truth.height, {0.0, 100.0});
  for (const simulator::TruthJunction& j : truth.junctions)
    if (j.visible) rig.visible.push_back(j);
  return cache.emplace(side, std::move(rig)).first->second;
}

decoder::FramedJunction At(const simulator::TruthJunction& j, int p, int q) {
  return {{j.image.x(), j.image.y()}, p, q};
}

// Line 0's part (lines 0-3, rows offset by -2 as a decode's relative rows
// may be) and an island (lines from `first_line`, labelled from p = 0, rows
// offset by -4, or -5 to keep p + v's parity): the shift that places it is
// (first_line, 2 or 3).
struct Split {
  std::vector<decoder::FramedJunction> labelled, island;
};
Split SplitAt(const PlaneRig& rig, int first_line, int min_row = -100, int max_row = 100) {
  Split s;
  for (const simulator::TruthJunction& j : rig.visible) {
    if (j.p <= 3) s.labelled.push_back(At(j, j.p, j.v - 2));
    if (j.p >= first_line && j.v >= min_row && j.v <= max_row)
      s.island.push_back(At(j, j.p - first_line, j.v - 4 - first_line % 2));
  }
  return s;
}

class IslandPlacement : public ::testing::TestWithParam<Side> {};

TEST_P(IslandPlacement, AnIslandIsPlacedAtItsOneShift) {
  const PlaneRig& rig = Rig(GetParam());
  const auto geometry = LabelGeometryOfCalibration(rig.calibration);
  ASSERT_NE(geometry, nullptr);
  for (int first_line : {6, 9}) {
    const Split s = SplitAt(rig, first_line);
    ASSERT_GE(s.island.size(), 50u);
    std::string why;
    const auto shift = geometry->PlaceIsland(s.labelled, s.island, &why);
    ASSERT_TRUE(shift.has_value()) << why;
    EXPECT_EQ(shift->dp, first_line);
    EXPECT_EQ(shift->dq, 2 + first_line % 2);
  }
}

TEST_P(IslandPlacement, LineZerosPartTakenTwoLinesOffIsMovedBack) {
  const PlaneRig& rig = Rig(GetParam());
  const auto geometry = LabelGeometryOfCalibration(rig.calibration);
  std::vector<decoder::FramedJunction> wrong;  // line 2 taken for line 0
  for (const simulator::TruthJunction& j : rig.visible)
    if (j.p >= 2 && j.p <= 8) wrong.push_back(At(j, j.p - 2, j.v));
  std::string why;
  const auto shift = geometry->PlaceIsland(wrong, wrong, &why);
  ASSERT_TRUE(shift.has_value()) << why;
  EXPECT_EQ(shift->dp, 2);
  std::vector<decoder::FramedJunction> right;
  for (const simulator::TruthJunction& j : rig.visible)
    if (j.p <= 6) right.push_back(At(j, j.p, j.v - 2));
  const auto none = geometry->PlaceIsland(right, right, &why);
  ASSERT_TRUE(none.has_value()) << why;
  EXPECT_EQ(none->dp, 0);
  EXPECT_EQ(none->dq, 0);
}

TEST_P(IslandPlacement, ALabelOffItsRowIsRuledOutTheOthersKept) {
  const PlaneRig& rig = Rig(GetParam());
  const auto geometry = LabelGeometryOfCalibration(rig.calibration);
  std::vector<decoder::FramedJunction> labelled;
  for (const simulator::TruthJunction& j : rig.visible)
    if (j.p <= 8) labelled.push_back(At(j, j.p, j.v - 2));
  ASSERT_GE(labelled.size(), 40u);
  std::vector<char> out = geometry->RuleOut(labelled);
  EXPECT_EQ(std::count(out.begin(), out.end(), 1), 0);
  labelled[10].q += 2;  // two rows off: the same kind, another row
  labelled[20].p += 1;  // one line off: the ray meets that plane off every row of the parity
  labelled[20].q += 1;
  out = geometry->RuleOut(labelled);
  EXPECT_EQ(out[10], 1);
  EXPECT_EQ(out[20], 1);
  EXPECT_EQ(std::count(out.begin(), out.end(), 1), 2);
  // Too few junctions to fix the rows: nothing is judged.
  labelled.resize(5);
  out = geometry->RuleOut(labelled);
  EXPECT_EQ(std::count(out.begin(), out.end(), 1), 0);
}

TEST_P(IslandPlacement, NoiseOfAPixelStillPlacesIt) {
  const PlaneRig& rig = Rig(GetParam());
  const auto geometry = LabelGeometryOfCalibration(rig.calibration);
  Split s = SplitAt(rig, 7);
  std::mt19937 random(5);
  std::uniform_real_distribution<double> jitter(-0.5, 0.5);
  for (decoder::FramedJunction& j : s.island)
    j.position += cv::Point2d(jitter(random), jitter(random));
  std::string why;
  const auto shift = geometry->PlaceIsland(s.labelled, s.island, &why);
  ASSERT_TRUE(shift.has_value()) << why;
  EXPECT_EQ(shift->dp, 7);
  EXPECT_EQ(shift->dq, 3);
}

TEST_P(IslandPlacement, AnIslandOffItsRowsIsRefused) {
  const PlaneRig& rig = Rig(GetParam());
  const auto geometry = LabelGeometryOfCalibration(rig.calibration);
  Split s = SplitAt(rig, 7);
  // Every junction half a row spacing (of this rig, about 5 px) lower in
  // turn: no shift puts them on whole rows.
  for (size_t k = 0; k < s.island.size(); k += 2) s.island[k].position.y += 3.0;
  std::string why;
  EXPECT_FALSE(geometry->PlaceIsland(s.labelled, s.island, &why).has_value());
  EXPECT_NE(why.find("rows"), std::string::npos) << why;
}

TEST_P(IslandPlacement, OutsideTheMeasuringVolumeNothingIsPlaced) {
  PlaneRig rig = Rig(GetParam());
  rig.calibration.screen_views = {{"", 200.0}, {"", 300.0}};  // the plane at z = 0 is far below
  IslandPlacementParams params;
  params.volume_margin_mm = 10.0;
  const auto geometry = LabelGeometryOfCalibration(rig.calibration, params);
  const Split s = SplitAt(rig, 7);
  std::string why;
  EXPECT_FALSE(geometry->PlaceIsland(s.labelled, s.island, &why).has_value());
  EXPECT_NE(why.find("measuring volume"), std::string::npos) << why;
}

TEST_P(IslandPlacement, TooFewJunctionsAreNotJudged) {
  const PlaneRig& rig = Rig(GetParam());
  const auto geometry = LabelGeometryOfCalibration(rig.calibration);
  Split s = SplitAt(rig, 7);
  std::string why;
  std::vector<decoder::FramedJunction> few(s.island.begin(), s.island.begin() + 5);
  EXPECT_FALSE(geometry->PlaceIsland(s.labelled, few, &why).has_value());
  EXPECT_NE(why.find("the island has 5 junctions"), std::string::npos) << why;
  s.labelled.resize(3);
  EXPECT_FALSE(geometry->PlaceIsland(s.labelled, s.island, &why).has_value());
  EXPECT_NE(why.find("line 0's part"), std::string::npos) << why;
}

INSTANTIATE_TEST_SUITE_P(BothSides, IslandPlacement, ::testing::Values(Side::kLeft, Side::kRight),
                         [](const ::testing::TestParamInfo<Side>& side) {
                           return std::string(pattern::ToString(side.param));
                         });

TEST(IslandPlacementParams, NeedsAProjectorMatrixAndValidNumbers) {
  calibration::SideCalibration cal = Rig(Side::kLeft).calibration;
  IslandPlacementParams bad;
  bad.min_rival_ratio = 0.5;
  std::string why;
  EXPECT_FALSE(bad.IsValid(&why));
  EXPECT_NE(why.find("min_rival_ratio"), std::string::npos);
  EXPECT_THROW(LabelGeometryOfCalibration(cal, bad), std::invalid_argument);
  cal.projector_matrix.reset();
  EXPECT_EQ(LabelGeometryOfCalibration(cal), nullptr);
}

}  // namespace
}  // namespace bsls::reconstruction
