#include "bsls/pattern/brick_pattern.h"

#include <cmath>

namespace bsls::pattern {
namespace {

bool IsEven(int n) { return n % 2 == 0; }

}  // namespace

bool PatternSpec::IsValid(std::string* error) const {
  auto fail = [error](const char* why) {
    if (error) *error = why;
    return false;
  };
  if (lines < 2) return fail("pattern needs at least 2 vertical lines");
  if (lines > 200) return fail("pattern has more than 200 vertical lines");
  if (rows < 1) return fail("pattern needs at least 1 row on each side of v = 0");
  if (rows > 500) return fail("pattern has more than 500 rows");
  if (!(stroke_width > 0.0 && stroke_width < 0.5))
    return fail("stroke width must lie in (0, 0.5) line pitches");
  return true;
}

std::string_view ToString(Side side) { return side == Side::kLeft ? "left" : "right"; }

std::string_view ToString(JunctionKind kind) {
  return kind == JunctionKind::kDirect ? "direct" : "corresponding";
}

std::optional<Side> ParseSide(std::string_view text) {
  if (text == "left") return Side::kLeft;
  if (text == "right") return Side::kRight;
  return std::nullopt;
}

Slide BrickSlideFor(Side side) {
  return side == Side::kLeft ? Slide::kLeftBrick : Slide::kRightBrick;
}

double UFromS(Side side, double s) { return side == Side::kLeft ? -s : s; }
double SFromU(Side side, double u) { return side == Side::kLeft ? -u : u; }

std::optional<JunctionKind> JunctionAt(const PatternSpec& spec, int p, int v) {
  if (v < -spec.rows || v > spec.rows) return std::nullopt;
  return JunctionOnRowParity(spec, p, v);
}

std::optional<JunctionKind> JunctionOnRowParity(const PatternSpec& spec, int p, int v) {
  if (p < 0 || p >= spec.lines) return std::nullopt;
  // Segment (p, p+1) lies on rows v = p (mod 2): direct on p, corresponding on p+1.
  const bool direct_row = IsEven(v - p);
  if (direct_row) {
    if (p + 1 < spec.lines) return JunctionKind::kDirect;
    return std::nullopt;  // last line has nothing to its outer side
  }
  if (p >= 1) return JunctionKind::kCorresponding;
  return std::nullopt;  // line 0 has nothing on its inner side
}

std::vector<SlideJunction> AllJunctions(const PatternSpec& spec) {
  std::vector<SlideJunction> out;
  for (int p = 0; p < spec.lines; ++p)
    for (int v = -spec.rows; v <= spec.rows; ++v)
      if (auto kind = JunctionAt(spec, p, v)) out.push_back({p, v, *kind});
  return out;
}

bool InStroke(const PatternSpec& spec, Slide slide, double s, double t) {
  const double half = spec.stroke_width / 2.0;
  if (slide == Slide::kReferenceCross) {
    const double s_max = spec.lines - 1 + half;
    const double t_max = spec.rows + half;
    if (std::abs(s) > s_max || std::abs(t) > t_max) return false;
    return std::abs(s) <= half || std::abs(t) <= half;
  }
  const Side side = slide == Slide::kLeftBrick ? Side::kLeft : Side::kRight;
  const double u = UFromS(side, s);
  const double v = t;
  if (u < -half || u > spec.lines - 1 + half) return false;
  if (v < -spec.rows - half || v > spec.rows + half) return false;
  // Vertical lines.
  const double nearest_p = std::round(u);
  if (std::abs(u - nearest_p) <= half) return true;
  // Horizontal segment between p = floor(u) and p + 1 on rows v = p (mod 2).
  const int p = static_cast<int>(std::floor(u));
  if (p < 0 || p + 1 >= spec.lines) return false;
  const double nearest_v = std::round(v);
  if (std::abs(v - nearest_v) > half) return false;
  return IsEven(static_cast<int>(nearest_v) - p);
}

int ImageDirectionOfIncreasingP(Side side) { return side == Side::kLeft ? -1 : +1; }

}  // namespace bsls::pattern
