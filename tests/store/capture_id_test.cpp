// Capture ids: well-formedness, uniqueness and time order.
#include "bsls/store/capture_id.h"

#include <gtest/gtest.h>

#include <set>
#include <thread>
#include <vector>

namespace bsls::store {
namespace {

TEST(CaptureIdTest, ParseAcceptsOnly32LowerCaseHexDigits) {
  EXPECT_TRUE(CaptureId::Parse("0123456789abcdef0123456789abcdef"));
  EXPECT_FALSE(CaptureId::Parse("0123456789ABCDEF0123456789abcdef"));
  EXPECT_FALSE(CaptureId::Parse("0123456789abcdef0123456789abcde"));
  EXPECT_FALSE(CaptureId::Parse("0123456789abcdef0123456789abcdef0"));
  EXPECT_FALSE(CaptureId::Parse("../0123456789abcdef0123456789abc"));
  EXPECT_FALSE(CaptureId::Parse(""));
}

TEST(CaptureIdTest, IdsAreUniqueAndIncreasingEvenWhenTheClockGoesBack) {
  CaptureIdGenerator generator;
  const auto now = std::chrono::system_clock::now();
  std::vector<CaptureId> ids;
  for (int i = 0; i < 1000; ++i) {
    // Many ids in the same millisecond, then a clock step backwards.
    ids.push_back(generator.Next(i < 900 ? now : now - std::chrono::seconds(5)));
  }
  for (std::size_t i = 1; i < ids.size(); ++i) EXPECT_LT(ids[i - 1], ids[i]) << i;
  const CaptureId later = generator.Next(now + std::chrono::seconds(1));
  EXPECT_LT(ids.back(), later);
  EXPECT_TRUE(CaptureId::Parse(later.str()));
}

TEST(CaptureIdTest, ConcurrentCallersGetDistinctIds) {
  CaptureIdGenerator generator;
  std::vector<std::vector<std::string>> made(4);
  std::vector<std::thread> threads;
  for (int t = 0; t < 4; ++t) {
    threads.emplace_back([&, t] {
      for (int i = 0; i < 500; ++i) {
        made[t].push_back(generator.Next(std::chrono::system_clock::now()).str());
      }
    });
  }
  for (auto& thread : threads) thread.join();
  std::set<std::string> all;
  for (const auto& list : made) all.insert(list.begin(), list.end());
  EXPECT_EQ(all.size(), 2000u);
}

TEST(CaptureIdTest, TwoGeneratorsDoNotCollide) {
  CaptureIdGenerator a;
  CaptureIdGenerator b;
  const auto now = std::chrono::system_clock::now();
  EXPECT_NE(a.Next(now), b.Next(now));
}

}  // namespace
}  // namespace bsls::store
