#include "bsls/common/cancellation.h"

#include <gtest/gtest.h>

#include <string>

namespace bsls {
namespace {

TEST(Cancellation, ADefaultOneNeverAsksToStop) {
  const Cancellation none;
  EXPECT_FALSE(none.Requested());
  EXPECT_NO_THROW(none.ThrowIfRequested("anything"));
}

TEST(Cancellation, AsksWhenItsFunctionSaysSoAndNamesWhere) {
  bool stop = false;
  const Cancellation token([&stop] { return stop; });
  EXPECT_FALSE(token.Requested());
  EXPECT_NO_THROW(token.ThrowIfRequested("the ridges"));
  stop = true;
  EXPECT_TRUE(token.Requested());
  try {
    token.ThrowIfRequested("the ridges");
    FAIL() << "no Cancelled thrown";
  } catch (const Cancelled& e) {
    EXPECT_EQ(std::string(e.what()), "cancelled during the ridges");
  }
}

}  // namespace
}  // namespace bsls
