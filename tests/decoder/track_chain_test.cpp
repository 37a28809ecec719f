// What is the track chain's (DecodeChain::kTracks) own: the targets
// on objects and faces hold it with the skeleton chain in decoder_test.cpp.
#include <gtest/gtest.h>

#include <algorithm>
#include <memory>
#include <opencv2/core/utility.hpp>
#include <optional>
#include <string>
#include <vector>

#include "bsls/decoder/decode_output.h"
#include "bsls/decoder/decoder.h"
#include "decoder_evaluation.h"

namespace bsls::decoder::test {
namespace {

DecodeParams TrackChain() {
  DecodeParams params;
  params.chain = DecodeChain::kTracks;
  return params;
}

TEST(TrackChain, TheResultDoesNotDependOnTheThreadCount) {
  const simulator::Frame frame = RenderFrame(SurfaceKind::kFace, Side::kLeft, 1);
  const int threads = cv::getNumThreads();
  cv::setNumThreads(1);
  const DecodeResult one = Decode(frame.image, Side::kLeft, TrackChain());
  cv::setNumThreads(std::max(threads, 2));
  const DecodeResult two = Decode(frame.image, Side::kLeft, TrackChain());
  cv::setNumThreads(threads);
  ASSERT_TRUE(one.ok && two.ok);
  ASSERT_NO_FATAL_FAILURE(ExpectSameJunctions(one, two));
  ASSERT_EQ(one.lines.size(), two.lines.size());
  for (size_t i = 0; i < one.lines.size(); ++i) EXPECT_EQ(one.lines[i].points, two.lines[i].points);
}

// The tracks are drawn into the skeleton image only when asked, and asking
// changes nothing else.
TEST(TrackChain, DrawsItsTracksOnlyWhenAsked) {
  const simulator::Frame frame = RenderFrame(SurfaceKind::kFace, Side::kLeft, 1);
  const DecodeResult plain = Decode(frame.image, Side::kLeft, TrackChain());
  ASSERT_TRUE(plain.ok) << plain.error;
  EXPECT_TRUE(plain.skeleton.empty());
  DecodeParams params = TrackChain();
  params.draw_tracks = true;
  const DecodeResult drawn = Decode(frame.image, Side::kLeft, params);
  ASSERT_TRUE(drawn.ok) << drawn.error;
  ASSERT_EQ(drawn.skeleton.size(), frame.image.size());
  EXPECT_GT(cv::countNonZero(drawn.skeleton), 5000);
  ASSERT_NO_FATAL_FAILURE(ExpectSameJunctions(plain, drawn));
}

// A line broken at a junction whose label cannot be proven, where it goes
// on as the same line across the break (line 0 at the lips' fold on the
// thesis face), keeps its rows beside that junction: the surface and the
// join's mouth profile need them.
TEST(TrackChain, ALineKeepsItsRowsAcrossAnUnprovenJunctionBetweenTwoOfItsStretches) {
  const simulator::Frame frame = RenderFrame(SurfaceKind::kFace, Side::kLeft, 4);
  const DecodeResult r = Decode(frame.image, Side::kLeft, TrackChain());
  ASSERT_TRUE(r.ok) << r.error;
  const auto zero =
      std::find_if(r.lines.begin(), r.lines.end(), [](const DecodedLine& l) { return l.p == 0; });
  ASSERT_NE(zero, r.lines.end());
  // Line 0's x by row, and the unlabelled junctions lying on it with
  // centres of it a whole row spacing above and below.
  std::vector<double> x_of_row(frame.image.rows, -1.0);
  for (const cv::Point2d& c : zero->points) x_of_row[static_cast<int>(std::lround(c.y))] = c.x;
  const double spacing = 0.5 * frame.image.rows / 20.0;  // rows, about a brick row here
  int between = 0;
  for (const UnlabelledJunction& u : r.unlabelled) {
    const int y = static_cast<int>(std::lround(u.position.y));
    const int above = y - static_cast<int>(spacing), below = y + static_cast<int>(spacing);
    if (above < 0 || below >= frame.image.rows || x_of_row[above] < 0 || x_of_row[below] < 0)
      continue;
    if (std::abs(u.position.x - 0.5 * (x_of_row[above] + x_of_row[below])) > 12.0) continue;
    ++between;
    for (int row = y - 2; row <= y + 2; ++row)
      EXPECT_GE(x_of_row[row], 0.0) << "line 0 has no centre in row " << row
                                    << " beside the unproven junction at " << u.position;
  }
  EXPECT_GE(between, 1) << "the frame no longer shows the case";
}

TEST(TrackChain, FrameWithoutReferenceLineIsReportedNotGuessed) {
  simulator::ThesisSceneOptions options;
  options.reference_cross = true;
  const simulator::Frame cross = simulator::Render(
      simulator::ThesisScene(Side::kLeft, SurfaceKind::kPlane, options), simulator::RenderParams{});
  const DecodeResult r = Decode(cross.image, Side::kLeft, TrackChain());
  EXPECT_FALSE(r.ok);
  // One line has no spacing of stripes: refused before line 0 is looked for.
  EXPECT_NE(r.error.find("no stripe pattern"), std::string::npos) << r.error;

  simulator::Frame face = RenderFrame(SurfaceKind::kFace, Side::kLeft, 5);
  face.image.colRange(300, 512).setTo(6);
  const DecodeResult cut = Decode(face.image, Side::kLeft, TrackChain());
  EXPECT_FALSE(cut.ok);
  EXPECT_NE(cut.error.find("line 0"), std::string::npos) << cut.error;
}

// A calibration's geometry as a script (the real one, from a calibration,
// is tested in tests/reconstruction/island_placement_test.cpp): asked about
// line 0's component itself it answers `own`, about an island `island`.
class ScriptedGeometry final : public LabelGeometry {
 public:
  ScriptedGeometry(std::optional<LabelShift> own, std::optional<LabelShift> island)
      : own_(own), island_(island) {}
  std::optional<LabelShift> PlaceIsland(const std::vector<FramedJunction>& labelled,
                                        const std::vector<FramedJunction>& island,
                                        std::string* why) const override {
    const bool itself = labelled.size() == island.size();
    ++asked_[itself];
    if (why) *why = "scripted";
    return itself ? own_ : island_;
  }
  // Rules out every label on line rule_out_p (-1: none), or every one.
  std::vector<char> RuleOut(const std::vector<FramedJunction>& labelled) const override {
    std::vector<char> out;
    for (const FramedJunction& j : labelled) out.push_back(rule_out_all || j.p == rule_out_p);
    return out;
  }
  int rule_out_p = -1;
  bool rule_out_all = false;
  mutable int asked_[2] = {0, 0};  // islands, line 0's component

 private:
  std::optional<LabelShift> own_, island_;
};

TEST(TrackChain, TheGeometryMovesLineZerosComponentOrRefusesItOffTheSlide) {
  const simulator::Frame frame = RenderFrame(SurfaceKind::kFace, Side::kLeft, 1);
  const DecodeResult plain = Decode(frame.image, Side::kLeft, TrackChain());
  ASSERT_TRUE(plain.ok) << plain.error;
  int max_p = 0;
  for (const DecodedJunction& j : plain.junctions) max_p = std::max(max_p, j.p);
  ASSERT_LE(max_p + 2, 19);

  DecodeParams params = TrackChain();
  auto confirms = std::make_shared<ScriptedGeometry>(LabelShift{0, 0}, std::nullopt);
  params.geometry = confirms;
  const DecodeResult same = Decode(frame.image, Side::kLeft, params);
  ASSERT_TRUE(same.ok) << same.error;
  EXPECT_EQ(confirms->asked_[1], 1);
  EXPECT_EQ(same.line_zero_moved, 0);
  ASSERT_NO_FATAL_FAILURE(ExpectSameJunctions(plain, same));

  params.geometry = std::make_shared<ScriptedGeometry>(LabelShift{2, 0}, std::nullopt);
  const DecodeResult moved = Decode(frame.image, Side::kLeft, params);
  ASSERT_TRUE(moved.ok) << moved.error;
  EXPECT_EQ(moved.line_zero_moved, 2);
  // Every junction moved by two lines; line 0, now line 2, has junctions
  // of both kinds in the pattern, and those between two seen ones are
  // placed from them (thesis 5.1.4.6), the only ones added.
  std::vector<DecodedJunction> kept;
  for (const DecodedJunction& j : moved.junctions) {
    if (j.interpolated && j.p == 2 &&
        std::none_of(plain.junctions.begin(), plain.junctions.end(),
                     [&](const DecodedJunction& k) { return k.p == 0 && k.q == j.q; })) {
      continue;
    }
    kept.push_back(j);
  }
  EXPECT_GT(moved.junctions.size(), kept.size());
  ASSERT_EQ(kept.size(), plain.junctions.size());
  for (size_t k = 0; k < plain.junctions.size(); ++k) {
    EXPECT_EQ(kept[k].p, plain.junctions[k].p + 2);
    EXPECT_EQ(kept[k].q, plain.junctions[k].q);
    EXPECT_EQ(kept[k].position, plain.junctions[k].position);
  }
  ASSERT_EQ(moved.lines.size(), plain.lines.size());
  EXPECT_EQ(moved.lines.front().p, plain.lines.front().p + 2);

  params.geometry = std::make_shared<ScriptedGeometry>(LabelShift{20, 0}, std::nullopt);
  const DecodeResult off = Decode(frame.image, Side::kLeft, params);
  EXPECT_FALSE(off.ok);
  EXPECT_NE(off.error.find("off the slide"), std::string::npos) << off.error;
}

TEST(TrackChain, LabelsTheGeometryRulesOutAreReportedUnlabelled) {
  const simulator::Frame frame = RenderFrame(SurfaceKind::kFace, Side::kLeft, 1);
  const DecodeResult plain = Decode(frame.image, Side::kLeft, TrackChain());
  ASSERT_TRUE(plain.ok) << plain.error;
  const auto on_line_3 = std::count_if(plain.junctions.begin(), plain.junctions.end(),
                                       [](const DecodedJunction& j) { return j.p == 3; });
  ASSERT_GT(on_line_3, 5);
  DecodeParams params = TrackChain();
  auto geometry = std::make_shared<ScriptedGeometry>(LabelShift{0, 0, {}}, std::nullopt);
  geometry->rule_out_p = 3;
  params.geometry = geometry;
  const DecodeResult judged = Decode(frame.image, Side::kLeft, params);
  ASSERT_TRUE(judged.ok) << judged.error;
  EXPECT_EQ(judged.junctions.size() + on_line_3, plain.junctions.size());
  EXPECT_EQ(judged.unlabelled.size(), plain.unlabelled.size() + on_line_3);
  EXPECT_EQ(judged.ruled_out, on_line_3);
  for (const DecodedJunction& j : judged.junctions) EXPECT_NE(j.p, 3);

  // Most of line 0's component off its rows: its labels are refuted.
  geometry->rule_out_all = true;
  const DecodeResult refuted = Decode(frame.image, Side::kLeft, params);
  EXPECT_FALSE(refuted.ok);
  EXPECT_NE(refuted.error.find("geometry refutes the labels"), std::string::npos) << refuted.error;
}

TEST(TrackChain, OutputsFollowTheContracts) {
  const simulator::Frame frame = RenderFrame(SurfaceKind::kPlane, Side::kRight, 7);
  DecodeParams params = TrackChain();
  params.q_offset = 4;
  params.draw_tracks = true;
  const DecodeResult r = Decode(frame.image, Side::kRight, params);
  ASSERT_TRUE(r.ok) << r.error;
  EXPECT_TRUE(r.q_absolute);
  const nlohmann::json j = ToJson(r);
  EXPECT_EQ(j["side"], "right");
  EXPECT_EQ(j["junctions"].size(), r.junctions.size());
  for (size_t i = 1; i < r.junctions.size(); ++i) {
    const auto& a = r.junctions[i - 1];
    const auto& b = r.junctions[i];
    EXPECT_TRUE(a.p < b.p || (a.p == b.p && a.q < b.q)) << "junctions out of order";
  }
  const cv::Mat overlay = RenderOverlay(frame.image, r);
  EXPECT_EQ(overlay.size(), frame.image.size());
  EXPECT_EQ(r.skeleton.size(), frame.image.size());
  EXPECT_GT(r.times.total_ms, 0.0);
}

}  // namespace
}  // namespace bsls::decoder::test
