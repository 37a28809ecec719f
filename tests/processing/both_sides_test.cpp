#include "bsls/session/both_sides.h"

#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <stdexcept>
#include <string>
#include <thread>

namespace bsls::session {
namespace {

using namespace std::chrono_literals;

TEST(RunBothSides, TheLeftRunsOnItsOwnThreadBesideTheRight) {
  const std::thread::id caller = std::this_thread::get_id();
  std::atomic<bool> left_started{false}, right_started{false};
  // Each side waits (bounded) until the other has started: they only both
  // see the other started when they run at the same time.
  auto wait_for = [](const std::atomic<bool>& flag) {
    for (int i = 0; i < 2000 && !flag; ++i) std::this_thread::sleep_for(1ms);
    return flag.load();
  };
  const auto [left, right] = RunBothSides(
      [&] {
        left_started = true;
        return std::make_pair(std::this_thread::get_id(), wait_for(right_started));
      },
      [&] {
        right_started = true;
        return std::make_pair(std::this_thread::get_id(), wait_for(left_started));
      });
  EXPECT_NE(left.first, caller);
  EXPECT_EQ(right.first, caller);
  EXPECT_TRUE(left.second);
  EXPECT_TRUE(right.second);
}

TEST(RunBothSides, WhenBothFailTheLeftSidesErrorIsThrown) {
  try {
    RunBothSides([]() -> int { throw std::runtime_error("left frame: bad"); },
                 []() -> int { throw std::runtime_error("right frame: bad"); });
    FAIL() << "no exception";
  } catch (const std::runtime_error& e) {
    EXPECT_EQ(std::string(e.what()), "left frame: bad");
  }
}

TEST(RunBothSides, TheRightSidesErrorWaitsForTheLeftToFinish) {
  std::atomic<bool> left_done{false};
  try {
    RunBothSides(
        [&] {
          std::this_thread::sleep_for(50ms);
          left_done = true;
          return 1;
        },
        []() -> int { throw std::invalid_argument("right calibration: wrong side"); });
    FAIL() << "no exception";
  } catch (const std::invalid_argument& e) {
    EXPECT_EQ(std::string(e.what()), "right calibration: wrong side");
  }
  // Nothing of the left side runs on after the call returned.
  EXPECT_TRUE(left_done);
}

}  // namespace
}  // namespace bsls::session
