// The SlideController's real code driving the emulated slide mechanism at the
// GPIO line level: changes with and without select lines, the in-place
// timeout, lamp, focus, active-low wiring, concurrency, the listener, config
// validation, and libgpiod on a chip that is not there.
#include "bsls/slides/slide_controller.h"

#include <gtest/gtest.h>

#include <thread>
#include <vector>

#include "bsls/slides/emulated_slide_changer.h"

namespace bsls::slides {
namespace {

using std::chrono::milliseconds;

SlideControllerConfig Fast() {
  SlideControllerConfig config;
  config.pulse = milliseconds(12);
  config.settle = milliseconds(20);
  config.change_timeout = milliseconds(1000);
  config.focus_step = milliseconds(1);
  config.emulated_travel = milliseconds(30);
  return config;
}

struct Rig {
  EmulatedSlideChanger* mechanism = nullptr;
  std::unique_ptr<SlideController> controller;
};

Rig Open(const SlideControllerConfig& config) {
  auto mechanism = std::make_unique<EmulatedSlideChanger>(config);
  Rig rig;
  rig.mechanism = mechanism.get();
  auto opened = SlideController::Open(std::move(mechanism), config);
  EXPECT_TRUE(opened.ok()) << opened.status().ToString();
  if (opened.ok()) rig.controller = std::move(opened).value();
  return rig;
}

Clock::time_point In(milliseconds ms) { return Clock::now() + ms; }

TEST(SlideController, CountsAdvancesRoundTheCarousel) {
  Rig rig = Open(Fast());
  ASSERT_TRUE(rig.controller);
  EXPECT_EQ(rig.controller->State().slide, 1);
  EXPECT_TRUE(rig.controller->State().in_place);
  ASSERT_TRUE(rig.controller->ChangeTo(3, In(milliseconds(2000))).ok());
  EXPECT_EQ(rig.mechanism->position(), 3);
  EXPECT_EQ(rig.mechanism->advances(), 2);
  EXPECT_EQ(rig.controller->State().slide, 3);
  EXPECT_TRUE(rig.controller->State().in_place);
  ASSERT_TRUE(rig.controller->ChangeTo(1, In(milliseconds(2000))).ok());  // wraps 3 -> 1
  EXPECT_EQ(rig.mechanism->position(), 1);
  EXPECT_EQ(rig.mechanism->advances(), 3);
  ASSERT_TRUE(rig.controller->ChangeTo(1, In(milliseconds(2000))).ok());  // already there
  EXPECT_EQ(rig.mechanism->advances(), 3);
}

TEST(SlideController, SelectLinesGoStraightToTheSlide) {
  SlideControllerConfig config = Fast();
  config.select0_line = 10;
  config.select1_line = 11;
  Rig rig = Open(config);
  ASSERT_TRUE(rig.controller);
  for (int slide : {3, 2, 1, 3}) {
    ASSERT_TRUE(rig.controller->ChangeTo(slide, In(milliseconds(2000))).ok()) << slide;
    EXPECT_EQ(rig.mechanism->position(), slide);
  }
  EXPECT_EQ(rig.mechanism->advances(), 4);  // one pulse per change
}

TEST(SlideController, ActiveLowWiringWorksTheSame) {
  SlideControllerConfig config = Fast();
  config.active_low = true;
  Rig rig = Open(config);
  ASSERT_TRUE(rig.controller);
  EXPECT_TRUE(rig.controller->State().in_place);
  ASSERT_TRUE(rig.controller->ChangeTo(2, In(milliseconds(2000))).ok());
  EXPECT_EQ(rig.mechanism->position(), 2);
  ASSERT_TRUE(rig.controller->SetLamp(true).ok());
  EXPECT_TRUE(rig.mechanism->lamp_lit());
}

TEST(SlideController, JammedCarouselTimesOutWithinBoundAndRecovers) {
  SlideControllerConfig config = Fast();
  config.change_timeout = milliseconds(150);
  Rig rig = Open(config);
  ASSERT_TRUE(rig.controller);
  rig.mechanism->SetFaults({.jammed = true});
  const Clock::time_point start = Clock::now();
  const Status status = rig.controller->ChangeTo(2, In(milliseconds(5000)));
  const auto took = std::chrono::duration_cast<milliseconds>(Clock::now() - start);
  EXPECT_EQ(status.code(), ErrorCode::kDeadlineExceeded);
  EXPECT_NE(status.message().find("slide 2 not confirmed in place"), std::string::npos)
      << status.message();
  EXPECT_LT(took, milliseconds(150 + 200));
  const SlideState state = rig.controller->State();
  EXPECT_EQ(state.slide, 0);
  EXPECT_FALSE(state.in_place);
  EXPECT_FALSE(state.moving);
  EXPECT_EQ(state.last_error, status.message());

  rig.mechanism->SetFaults({});  // freed: the carousel finishes its move to 2
  ASSERT_TRUE(rig.controller->ChangeTo(2, In(milliseconds(2000))).ok());
  EXPECT_EQ(rig.mechanism->position(), 2);
  EXPECT_TRUE(rig.controller->State().last_error.empty());
}

TEST(SlideController, InPlaceStuckLowIsADeadlineNotAHang) {
  Rig rig = Open(Fast());
  ASSERT_TRUE(rig.controller);
  rig.mechanism->SetFaults({.in_place_stuck_at = 0});
  const Status status = rig.controller->ChangeTo(3, In(milliseconds(300)));
  EXPECT_EQ(status.code(), ErrorCode::kDeadlineExceeded) << status.ToString();
}

TEST(SlideController, UnknownSlideAndBadFocusAreRefusedNamingThem) {
  Rig rig = Open(Fast());
  ASSERT_TRUE(rig.controller);
  Status status = rig.controller->ChangeTo(4, In(milliseconds(1000)));
  EXPECT_EQ(status.code(), ErrorCode::kInvalidArgument);
  EXPECT_NE(status.message().find("slide 4"), std::string::npos);
  status = rig.controller->ChangeTo(0, In(milliseconds(1000)));
  EXPECT_EQ(status.code(), ErrorCode::kInvalidArgument);
  status = rig.controller->Focus(2000, In(milliseconds(1000)));
  EXPECT_EQ(status.code(), ErrorCode::kInvalidArgument);
  EXPECT_EQ(rig.mechanism->advances(), 0);
}

TEST(SlideController, LampAndFocusReachTheLines) {
  Rig rig = Open(Fast());
  ASSERT_TRUE(rig.controller);
  EXPECT_FALSE(rig.mechanism->lamp_lit());
  ASSERT_TRUE(rig.controller->SetLamp(true).ok());
  EXPECT_TRUE(rig.mechanism->lamp_lit());
  EXPECT_TRUE(rig.controller->State().lamp_on);
  ASSERT_TRUE(rig.controller->Focus(7, In(milliseconds(2000))).ok());
  ASSERT_TRUE(rig.controller->Focus(-3, In(milliseconds(2000))).ok());
  EXPECT_EQ(rig.mechanism->focus_steps(), 4);
  EXPECT_EQ(rig.controller->State().focus_position, 4);
  // A deadline too short for every step: the steps made are kept and said.
  const Status status = rig.controller->Focus(1000, In(milliseconds(30)));
  EXPECT_EQ(status.code(), ErrorCode::kDeadlineExceeded);
  EXPECT_EQ(rig.controller->State().focus_position, rig.mechanism->focus_steps());
}

TEST(SlideController, ConcurrentChangesAreSerialisedAndTheListenerSeesThem) {
  Rig rig = Open(Fast());
  ASSERT_TRUE(rig.controller);
  std::mutex mutex;
  std::vector<SlideState> seen;
  rig.controller->SetListener([&](const SlideState& state) {
    std::lock_guard lock(mutex);
    seen.push_back(state);
  });
  std::vector<std::thread> callers;
  std::atomic<int> ok{0};
  for (int slide : {2, 3, 1, 2}) {
    callers.emplace_back([&, slide] {
      if (rig.controller->ChangeTo(slide, In(milliseconds(5000))).ok()) ++ok;
    });
  }
  for (std::thread& t : callers) t.join();
  EXPECT_EQ(ok, 4);
  const SlideState final_state = rig.controller->State();
  EXPECT_EQ(final_state.slide, rig.mechanism->position());
  EXPECT_TRUE(final_state.in_place);
  std::lock_guard lock(mutex);
  ASSERT_FALSE(seen.empty());
  EXPECT_TRUE(seen.back().in_place);
  EXPECT_FALSE(seen.back().moving);
  bool saw_moving = false;
  for (const SlideState& s : seen) saw_moving |= s.moving;
  EXPECT_TRUE(saw_moving);
}

TEST(SlideControllerConfig, ValidationNamesTheField) {
  SlideControllerConfig config = Fast();
  config.lamp_line = config.advance_line;
  Status status = Validate(config);
  EXPECT_EQ(status.code(), ErrorCode::kInvalidArgument);
  EXPECT_NE(status.message().find("lamp_line"), std::string::npos) << status.message();
  config = Fast();
  config.select0_line = 9;
  EXPECT_NE(Validate(config).message().find("select1_line"), std::string::npos);
  config = Fast();
  config.initial_slide = 5;
  EXPECT_NE(Validate(config).message().find("initial_slide 5"), std::string::npos);
  config = Fast();
  config.change_timeout = milliseconds(1);
  EXPECT_NE(Validate(config).message().find("change_timeout"), std::string::npos);
  EXPECT_TRUE(Validate(Fast()).ok());
}

TEST(LibgpiodChip, AMissingChipIsACleanErrorNamingIt) {
  auto chip = OpenLibgpiodChip("bsls-no-such-chip");
  ASSERT_FALSE(chip.ok());
  EXPECT_TRUE(chip.status().code() == ErrorCode::kUnavailable ||
              chip.status().code() == ErrorCode::kPermissionDenied)
      << chip.status().ToString();
  EXPECT_NE(chip.status().message().find("bsls-no-such-chip"), std::string::npos);
}

}  // namespace
}  // namespace bsls::slides
