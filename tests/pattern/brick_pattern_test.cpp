#include "bsls/pattern/brick_pattern.h"

#include <gtest/gtest.h>

namespace bsls::pattern {
namespace {

TEST(BrickPattern, JunctionKindsFollowTheBrickRule) {
  PatternSpec spec;
  // Line 0: direct junctions on even rows only.
  EXPECT_EQ(JunctionAt(spec, 0, 0), JunctionKind::kDirect);
  EXPECT_EQ(JunctionAt(spec, 0, 1), std::nullopt);
  // Line 1: direct on odd rows, corresponding on even rows.
  EXPECT_EQ(JunctionAt(spec, 1, 1), JunctionKind::kDirect);
  EXPECT_EQ(JunctionAt(spec, 1, 2), JunctionKind::kCorresponding);
  // Last line: only corresponding junctions.
  EXPECT_EQ(JunctionAt(spec, spec.lines - 1, spec.lines - 1), std::nullopt);
  EXPECT_EQ(JunctionAt(spec, spec.lines - 1, spec.lines), JunctionKind::kCorresponding);
  EXPECT_EQ(JunctionAt(spec, 3, spec.rows + 1), std::nullopt);
}

TEST(BrickPattern, CountsMatchContracts) {
  PatternSpec spec;
  const auto all = AllJunctions(spec);
  // Line 0: the M+1 even rows; lines 1..N-2: all 2M+1 rows; the last line
  // has only its corresponding junctions, on the rows v = N (mod 2).
  const size_t rows = 2 * spec.rows + 1;
  const size_t last = (spec.lines % 2 == 0) ? spec.rows + 1 : spec.rows;
  EXPECT_EQ(all.size(), static_cast<size_t>(spec.rows + 1) + (spec.lines - 2) * rows + last);
}

TEST(BrickPattern, StrokesOfLeftSlideAreMirroredOnRightSlide) {
  PatternSpec spec;
  for (double s = -21.0; s <= 21.0; s += 0.037)
    for (double t = -25.0; t <= 25.0; t += 0.041)
      ASSERT_EQ(InStroke(spec, Slide::kLeftBrick, s, t), InStroke(spec, Slide::kRightBrick, -s, t))
          << s << "," << t;
}

TEST(BrickPattern, SegmentRowsAlternateBetweenColumns) {
  PatternSpec spec;
  const Side side = Side::kRight;  // u == s
  // Segment between lines 0 and 1 on even rows, between 1 and 2 on odd rows.
  EXPECT_TRUE(InStroke(spec, Slide::kRightBrick, SFromU(side, 0.5), 0.0));
  EXPECT_FALSE(InStroke(spec, Slide::kRightBrick, SFromU(side, 0.5), 1.0));
  EXPECT_TRUE(InStroke(spec, Slide::kRightBrick, SFromU(side, 1.5), 1.0));
  EXPECT_FALSE(InStroke(spec, Slide::kRightBrick, SFromU(side, 1.5), 0.0));
  // Nothing on the inner side of the reference line.
  EXPECT_FALSE(InStroke(spec, Slide::kRightBrick, SFromU(side, -0.5), 0.0));
  // Reference cross: both axes lit.
  EXPECT_TRUE(InStroke(spec, Slide::kReferenceCross, 0.0, 7.3));
  EXPECT_TRUE(InStroke(spec, Slide::kReferenceCross, -7.3, 0.0));
  EXPECT_FALSE(InStroke(spec, Slide::kReferenceCross, 3.5, 3.5));
}

TEST(BrickPattern, SpecValidation) {
  std::string why;
  PatternSpec bad;
  bad.lines = 1;
  EXPECT_FALSE(bad.IsValid(&why));
  EXPECT_NE(why.find("vertical lines"), std::string::npos);
  EXPECT_TRUE(PatternSpec{}.IsValid(&why));
}

}  // namespace
}  // namespace bsls::pattern
