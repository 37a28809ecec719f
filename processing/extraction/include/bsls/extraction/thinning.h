// Line thinning (thesis 4.3): binary stripes to one-pixel-wide skeletons.
//
// Images: inputs are binary CV_8UC1 (any non-zero value is foreground);
// outputs are new CV_8UC1 images of the same size with 0 = background and
// 255 = skeleton. x = column, y = row (downwards), origin at the top-left
// pixel centre. Connectivity of the foreground is 8, of the background 4.
// Pixels outside the image count as background.
//
// Neighbourhood naming of thesis Figure 4.18 (p1 is the pixel itself):
//     p9 p2 p3
//     p8 p1 p4
//     p7 p6 p5
//
// Errors: empty or non-CV_8UC1 input and invalid parameters throw
// std::invalid_argument("<Function>: <reason>").
//
// Thread-safety: pure functions of their arguments. RecentreOnRidge smooths
// the grey image band by band on OpenCV's thread pool (cv::parallel_for_).
#ifndef BSLS_EXTRACTION_THINNING_H_
#define BSLS_EXTRACTION_THINNING_H_

#include <opencv2/core.hpp>
#include <string>

namespace bsls::extraction {

// Thesis 4.3.1: the line-following thinning with two pointers and an
// adaptive window (after [83]). Interpretation of the OCR'd text:
//  * The image is raster-scanned, rows top to bottom, each row right to left;
//    the first set pixel found is the right pointer PR.
//  * The run of the line in that row is grown leftwards across gaps of up to
//    `bridge_gap` black pixels; its left end is PL. The set (median) pixel is
//    (PL + PR) / 2 (rounded down).
//  * Direction: a structure that continues downwards (set pixels inside the
//    window below for more than (width - l) / 2 rows) is followed vertically,
//    row by row, the main direction; one wider than that is followed
//    horizontally, column by column, both ways from its middle.
//  * Following: the window of the next row (column) is [PL - l, PR + l]; the
//    set pixels inside it give the new PL, PR and median; the followed run is
//    erased and the median written to the skeleton, consecutive medians joined.
//  * Junction: when the set pixels of the next row continue beyond the window
//    by at least `min_branch_length` pixels, a horizontal branch leaves there.
//    It is followed horizontally away from the line until it meets the next
//    junction (a column whose run leaves its window: a vertical line) or ends;
//    then following returns to the vertical line (vertical has priority).
//  * End of line: nothing set inside the next window. An end that stops on
//    skeleton already drawn (within l + 1 rows ahead) is joined to it.
//  * Noise: black pixels inside the line are treated as white for up to
//    `max_split_rows` consecutive rows (thesis: five) -- gaps wider than
//    bridge_gap that split the run, and a side of the run that suddenly
//    disappears (the flank edge opening where a branch leaves); a split that
//    lasts longer is a fork and each branch is followed separately.
//  * Branches are joined to the line they leave with straight 8-connected
//    segments, and a branch that stops at a junction is joined to the nearest
//    skeleton pixel of the line it met (within margin + its half width + 2 px).
struct LineFollowingParams {
  int margin = 2;  // l of the thesis, pixels, >= 1
  // Black gaps of up to this many pixels inside a line's run are bridged
  // (the window "embraces the line"); on an edge image this pairs the two
  // flank edges of a stripe up to bridge_gap + 2 px wide. >= 0.
  int bridge_gap = 2;
  int max_split_rows = 5;     // rows a split run is still one line, >= 0
  int min_branch_length = 3;  // pixels beyond the window that make a junction, >= 1

  // True when the values are usable; otherwise says why.
  bool IsValid(std::string* error) const;
};

// Thesis 4.3.1: line-following thinning of a binary image.
cv::Mat LineFollowingThin(const cv::Mat& binary, const LineFollowingParams& params);

// Thesis 4.3.2, eq. 4.18-4.20: Zhang & Suen's parallel thinning [77]. Each
// iteration has two sub-steps; a contour pixel p1 is flagged when
//   (a) 2 <= N(p1) <= 6 (set neighbours), (b) S(p1) = 1 (0->1 transitions in
//   p2, p3, ..., p9, p2), (c) p2 p4 p6 = 0 and (d) p4 p6 p8 = 0 in step 1,
//   (c') p2 p4 p8 = 0 and (d') p2 p6 p8 = 0 in step 2,
// and the flagged pixels are deleted together; until nothing changes.
struct ZhangSuenParams {
  // The original parallel deletion erases 2x2 squares and two-pixel-thick
  // diagonal strokes completely. When true (default) the flagged pixels are
  // deleted one by one and a pixel is kept if, by then, deleting it would
  // change the topology (it is no longer 8-simple) or it has become an end
  // point; the result is the same elsewhere.
  bool preserve_topology = true;
  int max_iterations = 1000;  // safety bound, >= 1

  // True when the values are usable; otherwise says why.
  bool IsValid(std::string* error) const;
};

// Thesis 4.3.2: Zhang-Suen thinning of a binary image.
cv::Mat ZhangSuenThin(const cv::Mat& binary, const ZhangSuenParams& params = {});

// What MakeOnePixelWide does at a T-junction on a straight line. In
// 8-connectivity such a T is either a cluster (the T-centre, its two line
// neighbours and the branch's first pixel all touch each other) or a notch
// (the T-centre deleted, the line bending one pixel into the branch).
enum class TJunctionShape {
  // Keep the T-centre (a pixel with 3 or 4 set 4-neighbours): the junction
  // pixel stays on the line, where the junction is. The T-centre and its two
  // line neighbours have degree 3, the branch's first pixel degree 4;
  // consumers should merge 8-adjacent junction pixels into one junction.
  kCentreKept,
  // Delete it too: exactly one junction pixel (degree 3) per T, but one
  // pixel off the line towards the branch.
  kNotched,
};

// Makes an 8-connected skeleton strictly one pixel wide: repeatedly deletes
// pixels that have at least two set neighbours and are 8-simple (Yokoi's
// 8-connectivity number is 1, so deletion changes no connectivity and opens
// no hole) -- the corner pixels of staircases and of junction clusters --
// except T-centres when t_junctions is kCentreKept. Afterwards every pixel
// of a plain line has exactly 2 set neighbours and line ends have 1. Line
// ends are never shortened except for a one-pixel hook at a bent end.
cv::Mat MakeOnePixelWide(const cv::Mat& skeleton,
                         TJunctionShape t_junctions = TJunctionShape::kCentreKept);

// Ridge re-centring (not in the thesis): a binary thinning can only split an
// even-width mask off-centre, up to a pixel from the grey-level ridge. This
// moves plain-line skeleton pixels one pixel across their line (x for a
// pixel whose two neighbours lie in the rows above and below, y for one
// whose neighbours lie in the columns left and right) towards the brighter
// side of the grey image smoothed by `sigma`, when that side is at least
// `min_gain` grey levels brighter and the move keeps both neighbours
// adjacent and touches nothing else -- so topology and every pixel's degree
// are unchanged. Junction, end and corner pixels never move, nor do pixels
// within junction_clearance of a junction (where the grey ridge bends).
struct RecentreParams {
  double sigma = 2.5;          // px, Gaussian smoothing of the grey image, > 0
  double min_gain = 0.5;       // grey levels, >= 0
  int passes = 3;              // sweeps over the skeleton (a pixel moves <= 1 px per sweep), >= 1
  int junction_clearance = 3;  // px (Chebyshev) around junction pixels left alone, >= 0

  // True when the values are usable; otherwise says why.
  bool IsValid(std::string* error) const;
};

// Moves the skeleton onto the ridge of `grey` (CV_8UC1, same size).
cv::Mat RecentreOnRidge(const cv::Mat& skeleton, const cv::Mat& grey,
                        const RecentreParams& params = {});

}  // namespace bsls::extraction

#endif  // BSLS_EXTRACTION_THINNING_H_
