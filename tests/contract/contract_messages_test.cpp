// processing/contract: frames, sides, options and plans to and from the
// messages, and every malformed message refused with the field named.
#include <gtest/gtest.h>

#include "bsls/contract/frame_message.h"
#include "bsls/contract/processing_messages.h"

namespace bsls::contract {
namespace {

// The message's what() once `f` throws MessageError; fails the test otherwise.
template <typename F>
std::string RefusalOf(F&& f) {
  try {
    f();
  } catch (const MessageError& e) {
    return e.what();
  }
  ADD_FAILURE() << "no MessageError";
  return {};
}

TEST(FrameMessage, RoundTripsAnImageAndItsRowsThroughAStride) {
  cv::Mat image(3, 5, CV_8UC1);
  for (int y = 0; y < image.rows; ++y)
    for (int x = 0; x < image.cols; ++x) image.at<std::uint8_t>(y, x) = 10 * y + x;
  v1::Frame frame;
  ToFrameMessage(image(cv::Rect(1, 0, 3, 3)), &frame);  // not continuous
  EXPECT_EQ(frame.width(), 3u);
  EXPECT_EQ(frame.stride(), 3u);
  EXPECT_EQ(cv::norm(FrameView(frame, "frame"), image(cv::Rect(1, 0, 3, 3)), cv::NORM_INF), 0);

  // The same pixels with two bytes of padding a row.
  v1::Frame padded;
  padded.set_width(3);
  padded.set_height(3);
  padded.set_stride(5);
  padded.set_pixels(std::string(reinterpret_cast<const char*>(image.data), 15));
  EXPECT_EQ(cv::norm(FrameView(padded, "left"), image(cv::Rect(0, 0, 3, 3)), cv::NORM_INF), 0);
}

TEST(FrameMessage, MalformedFramesAreRefusedNamingTheField) {
  v1::Frame frame;
  frame.set_width(4);
  frame.set_height(2);
  frame.set_stride(4);
  frame.set_pixels(std::string(7, '\0'));
  EXPECT_NE(RefusalOf([&] { FrameView(frame, "right"); }).find("right: 7 bytes"),
            std::string::npos);
  frame.set_stride(3);
  EXPECT_NE(RefusalOf([&] { FrameView(frame, "right"); }).find("stride 3"), std::string::npos);
  frame.set_width(kMaxFrameSide + 1);
  EXPECT_NE(RefusalOf([&] { FrameView(frame, "frame"); }).find("frame: 4097 x 2"),
            std::string::npos);
  frame.set_width(0);
  EXPECT_NE(RefusalOf([&] { FrameView(frame, "frame"); }).find("1..4096"), std::string::npos);
}

TEST(ProcessingMessages, SidesBothWaysAndUnspecifiedRefused) {
  for (pattern::Side side : {pattern::Side::kLeft, pattern::Side::kRight})
    EXPECT_EQ(SideOf(ToProto(side), "side"), side);
  EXPECT_EQ(RefusalOf([] { SideOf(v1::SIDE_UNSPECIFIED, "side"); }),
            "side: must be SIDE_LEFT or SIDE_RIGHT");
}

TEST(ProcessingMessages, OptionsBecomeTheSideParameters) {
  v1::DecodeOptions decode;
  v1::SurfaceOptions surface;
  const reconstruction::SidePipelineParams defaults = SideParams(decode, surface);
  EXPECT_EQ(defaults.decode.extraction.method, extraction::ExtractionMethod::kModern);
  EXPECT_TRUE(defaults.decode.interpretation.enable_repair);
  EXPECT_EQ(defaults.planes, reconstruction::PlaneModelKind::kPerspective);
  EXPECT_EQ(defaults.reconstruction.mesh.strips, reconstruction::StripMethod::kStitched);
  EXPECT_FALSE(defaults.chain.has_value());

  decode.set_method(v1::DecodeOptions::METHOD_THESIS);
  decode.set_no_repair(true);
  surface.set_plane_model(v1::SurfaceOptions::PLANE_MODEL_PARALLEL);
  surface.set_strips(v1::SurfaceOptions::STRIP_METHOD_ROW_PAIRS);
  surface.set_smooth_lines(true);
  const reconstruction::SidePipelineParams chosen = SideParams(decode, surface);
  EXPECT_EQ(chosen.decode.extraction.method, extraction::ExtractionMethod::kThesis);
  EXPECT_FALSE(chosen.decode.interpretation.enable_repair);
  EXPECT_EQ(chosen.planes, reconstruction::PlaneModelKind::kParallel);
  EXPECT_EQ(chosen.reconstruction.mesh.strips, reconstruction::StripMethod::kRowPairs);
  EXPECT_TRUE(chosen.reconstruction.smooth_lines);
}

TEST(ProcessingMessages, UndefinedEnumNumbersAreRefusedNamingTheField) {
  v1::DecodeOptions decode;
  v1::SurfaceOptions surface;
  decode.set_method(static_cast<v1::DecodeOptions::Method>(77));
  EXPECT_EQ(RefusalOf([&] { SideParams(decode, surface); }),
            "decode.method: 77 is not one of the field's values");
  decode.Clear();
  surface.set_strips(static_cast<v1::SurfaceOptions::StripMethod>(-3));
  EXPECT_EQ(RefusalOf([&] { SideParams(decode, surface); }),
            "surface.strips: -3 is not one of the field's values");
  EXPECT_EQ(RefusalOf([] { JoinModeOf(static_cast<v1::ReconstructSessionRequest::Join>(9)); }),
            "join: 9 is not one of the field's values");
  EXPECT_EQ(JoinModeOf(v1::ReconstructSessionRequest::JOIN_FEATURES), session::JoinMode::kFeatures);
  EXPECT_EQ(JoinModeOf(v1::ReconstructSessionRequest::JOIN_SHARED), session::JoinMode::kShared);
}

TEST(ProcessingMessages, AMeasurementPlanRoundTrips) {
  measurement::MeasurementPlan plan;
  plan.heights = {{1.5, -2.0}};
  plan.distances = {{Eigen::Vector2d(0, 0), Eigen::Vector2d(10, 5)}};
  plan.areas = {{{0, 0}, {10, 0}, {10, 10}}};
  plan.lesions = {{{-5, -5}, {5, -5}, {5, 5}, {-5, 5}}};
  plan.lesion.reference = measurement::ReferenceKind::kQuadric;
  plan.lesion.ring_width_mm = 4.5;
  const measurement::MeasurementPlan back = PlanOf(ToProto(plan), 16);
  EXPECT_EQ(back.heights, plan.heights);
  EXPECT_EQ(back.distances, plan.distances);
  EXPECT_EQ(back.areas, plan.areas);
  EXPECT_EQ(back.lesions, plan.lesions);
  EXPECT_EQ(back.lesion.reference, measurement::ReferenceKind::kQuadric);
  EXPECT_EQ(back.lesion.ring_width_mm, 4.5);
}

TEST(ProcessingMessages, MalformedPlansAreRefusedNamingTheFigure) {
  measurement::MeasurementPlan plan;
  plan.heights = {{0, 0}, {1, 1}, {2, 2}};
  EXPECT_EQ(RefusalOf([&] { PlanOf(ToProto(plan), 2); }), "measurements: 3 figures, at most 2");
  v1::MeasurementPlan m;
  v1::Polygon* d = m.add_distances();
  for (int i = 0; i < 3; ++i) d->add_points()->set_x(i);
  EXPECT_EQ(RefusalOf([&] { PlanOf(m, 8); }), "measurements.distances[0]: give exactly two points");
  v1::MeasurementPlan r;
  r.set_reference(static_cast<v1::MeasurementPlan::Reference>(12));
  EXPECT_EQ(RefusalOf([&] { PlanOf(r, 8); }),
            "measurements.reference: 12 is not one of the field's values");
  v1::MeasurementPlan area;
  area.add_areas()->add_points();  // one point: no area
  EXPECT_EQ(RefusalOf([&] { PlanOf(area, 8); }).rfind("measurements: ", 0), 0u);
}

}  // namespace
}  // namespace bsls::contract
