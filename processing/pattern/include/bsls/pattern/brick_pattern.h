// The projected patterns of BSLS and their junction labels (contracts
// sections 1 and 2; thesis 2.1, 5.2, Figure 5.1).
//
// Slide coordinates:
//   (s, t)  the projector's slide plane in units of the vertical-line pitch d,
//           origin at the slide centre; s grows towards world +x, t grows
//           towards world -y (downwards, like image rows).
//   (u, v)  the brick pattern's own frame, also in units of d: line p lies at
//           u = p, a horizontal segment on row v. v == t. On the left-side
//           slide (slide 2) u = -s; on its mirror (slide 3) u = s.
//
// Thread-safety: everything here is a pure function of its arguments.
#ifndef BSLS_PATTERN_BRICK_PATTERN_H_
#define BSLS_PATTERN_BRICK_PATTERN_H_

#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace bsls::pattern {

// Which half of the face: left is world x < 0, seen by the left camera.
enum class Side { kLeft, kRight };

// Thesis Figure 1.1: slide 1 = reference cross, 2 = left brick, 3 = right brick.
enum class Slide { kReferenceCross = 1, kLeftBrick = 2, kRightBrick = 3 };

// A junction on line p whose segment leaves towards p+1 is direct; one whose
// segment comes from p-1 is corresponding (thesis 5.1.4).
enum class JunctionKind { kDirect, kCorresponding };

// N, M and stroke width of contracts section 1.
struct PatternSpec {
  int lines = 20;               // N: vertical lines p = 0 .. N-1
  int rows = 24;                // M: segment rows v = -M .. M
  double stroke_width = 0.125;  // w, in units of d, for every stroke

  // True when the numbers describe a drawable pattern; otherwise says why.
  bool IsValid(std::string* error) const;
};

// One junction of the projected pattern.
struct SlideJunction {
  int p = 0;  // vertical line, 0 = reference line
  int v = 0;  // slide row
  JunctionKind kind = JunctionKind::kDirect;
};

// Returns "left" or "right".
std::string_view ToString(Side side);
// Returns "direct" or "corresponding".
std::string_view ToString(JunctionKind kind);
// Parses "left" / "right"; nullopt for anything else.
std::optional<Side> ParseSide(std::string_view text);

// The brick slide projected for a side: slide 2 for left, 3 for right.
Slide BrickSlideFor(Side side);

// Pattern coordinate u of slide coordinate s for a side (u = -s on the left).
double UFromS(Side side, double s);
// Slide coordinate s of pattern coordinate u for a side (inverse of UFromS).
double SFromU(Side side, double u);

// The kind of the junction at (p, v), or nullopt when the pattern has none
// there (outside the pattern, or line 0 on an odd row).
std::optional<JunctionKind> JunctionAt(const PatternSpec& spec, int p, int v);
// The same for a row v known only up to an even offset (a relative label,
// contracts section 2): only v's parity is used, not its range.
std::optional<JunctionKind> JunctionOnRowParity(const PatternSpec& spec, int p, int v);

// Every junction of the brick pattern, ordered by p then v.
std::vector<SlideJunction> AllJunctions(const PatternSpec& spec);

// True when slide point (s, t) lies inside a transparent stroke of the slide.
// Strokes are w wide, centred on their line; vertical lines span
// v in [-M - w/2, M + w/2].
bool InStroke(const PatternSpec& spec, Slide slide, double s, double t);

// Image direction (+1 = towards larger image x) in which line numbers grow on
// a side, assuming the camera is upright: -1 on the left, +1 on the right.
int ImageDirectionOfIncreasingP(Side side);

}  // namespace bsls::pattern

#endif  // BSLS_PATTERN_BRICK_PATTERN_H_
