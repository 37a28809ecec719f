#include "bsls/common/status.h"

#include <gtest/gtest.h>

#include <memory>
#include <string>

namespace bsls {
namespace {

TEST(Status, OkAndErrorsSayWhatTheyAre) {
  const Status ok;
  EXPECT_TRUE(ok.ok());
  EXPECT_EQ(ok.code(), ErrorCode::kOk);
  EXPECT_EQ(ok.ToString(), "ok");
  const Status error(ErrorCode::kDataLoss, "frame 3 is short");
  EXPECT_FALSE(error.ok());
  EXPECT_EQ(error.ToString(), "data loss: frame 3 is short");
  EXPECT_EQ(ToString(ErrorCode::kResourceExhausted), "resource exhausted");
}

TEST(Result, HoldsAValueOrTheStatusWhyNot) {
  Result<std::unique_ptr<int>> value(std::make_unique<int>(7));
  ASSERT_TRUE(value.ok());
  EXPECT_TRUE(value.status().ok());
  EXPECT_EQ(**value, 7);
  const std::unique_ptr<int> taken = std::move(value).value();
  EXPECT_EQ(*taken, 7);
  const Result<int> error(Status(ErrorCode::kNotFound, "no capture 42"));
  EXPECT_FALSE(error.ok());
  EXPECT_EQ(error.status().code(), ErrorCode::kNotFound);
  EXPECT_EQ(error.status().message(), "no capture 42");
}

}  // namespace
}  // namespace bsls
