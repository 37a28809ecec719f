// Pruning of skeletons (thesis 4.4): removal of noise pixels, small
// components and short spurs.
//
// Images: inputs are binary CV_8UC1 skeletons (any non-zero value is set);
// outputs are new CV_8UC1 images, 0 / 255. Connectivity is 8. Degree of a
// pixel = number of set 8-neighbours: 1 = end point, 2 = line, >= 3 = junction.
// x = column, y = row; pixels outside the image count as background.
//
// Errors: empty or non-CV_8UC1 input and invalid parameters throw
// std::invalid_argument("<Function>: <reason>").
//
// Thread-safety: pure functions of their arguments.
#ifndef BSLS_EXTRACTION_PRUNING_H_
#define BSLS_EXTRACTION_PRUNING_H_

#include <opencv2/core.hpp>
#include <string>

#include "bsls/common/cancellation.h"

namespace bsls::extraction {

// Thesis 4.4, Figure 4.19: the pruning windows. The figure is unreadable in
// the OCR'd thesis; what survives is: four windows; a set pixel S, "don't
// care" pixels (*) and surrounding neighbourhood pixels p1..pn, with n up to
// 12; the image is scanned right to left; if all p1..pn are black, S and the
// * pixels are erased. Our interpretation: each window is an interior block
// (S plus the * pixels) and the one-pixel ring around it (p1..pn). The four
// windows have interiors 1x1 (ring of 8: an isolated pixel), 1x2 and 2x1
// (rings of 10: a two-pixel speck lying horizontally or vertically) and 2x2
// (ring of 12: any speck inside a 2x2 box). The scan goes row by row, top to
// bottom, each row right to left; S is the current set pixel and every
// placement of the interior that has S in its top row is tried; when the
// ring of a placement is entirely black the interior is erased.
// max_interior > 2 adds the interiors up to max_interior x max_interior
// (e.g. 3: rings of up to 16 pixels) for noisier skeletons.
struct PruningWindowParams {
  int max_interior = 2;  // largest interior side, pixels, 1..8 (thesis: 2)

  // True when the values are usable; otherwise says why.
  bool IsValid(std::string* error) const;
};

// Thesis 4.4: applies the pruning windows once over the image.
cv::Mat ApplyPruningWindows(const cv::Mat& skeleton, const PruningWindowParams& params = {});

// Spur pruning (not in the thesis, which leaves it to tracing, 4.4 / chapter 5).
// An end branch is the path from an end point (degree 1) through degree-2
// pixels up to the first junction pixel (degree >= 3) or to another end
// point. Branches are removed shortest first, re-checking the junction each
// time, so that of two short forks at a line end only the shorter goes.
struct SpurPruneParams {
  int max_spur_length = 6;  // pixels; end branches shorter than this are spurs, >= 1
  // true (default): only end branches that hang off a junction are pruned;
  // a line whose end is free (not attached to a junction) keeps its length.
  // false: classic pruning, every end branch shorter than max_spur_length
  // goes, so isolated short lines (< max_spur_length pixels) vanish too.
  bool keep_free_ends = true;
  int max_passes = 4;  // repeat while something changes, at most this often, >= 1

  // True when the values are usable; otherwise says why.
  bool IsValid(std::string* error) const;
};

// Removes spurs from a one-pixel-wide skeleton (see SpurPruneParams).
cv::Mat PruneSpurs(const cv::Mat& skeleton, const SpurPruneParams& params = {});

// Removes 8-connected components with fewer than min_pixels set pixels
// (min_pixels >= 1; 1 keeps everything). Asks `cancel` every few thousand
// components and between its passes over the image.
cv::Mat RemoveSmallComponents(const cv::Mat& binary, int min_pixels,
                              const Cancellation& cancel = {});

}  // namespace bsls::extraction

#endif  // BSLS_EXTRACTION_PRUNING_H_
