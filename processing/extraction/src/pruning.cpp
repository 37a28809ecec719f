#include "bsls/extraction/pruning.h"

#include <algorithm>
#include <bit>
#include <opencv2/imgproc.hpp>
#include <optional>
#include <utility>
#include <vector>

#include "bsls/extraction/thinning.h"
#include "input_checks.h"
#include "neighbourhood.h"
#include "skeleton_in_place.h"

namespace bsls::extraction {
namespace {

using internal::PaddedBinary;
using internal::RequireGrey8;
using internal::RequireValid;

bool IsSet(const cv::Mat& img, int x, int y) {
  return x >= 0 && y >= 0 && x < img.cols && y < img.rows && img.at<unsigned char>(y, x);
}

// True when the one-pixel ring around rows [y0, y0 + h) x columns [x0, x0 + w) is black.
bool RingIsBlack(const cv::Mat& img, int x0, int y0, int w, int h) {
  for (int x = x0 - 1; x <= x0 + w; ++x)
    if (IsSet(img, x, y0 - 1) || IsSet(img, x, y0 + h)) return false;
  for (int y = y0; y < y0 + h; ++y)
    if (IsSet(img, x0 - 1, y) || IsSet(img, x0 + w, y)) return false;
  return true;
}

// An end branch found by tracing from an end point.
struct Branch {
  std::vector<size_t> pixels;      // from the end point inwards, junction excluded
  std::optional<size_t> junction;  // the junction it hangs off, if any
};

// Traces from end point `start` along degree-2 pixels; stops at a junction,
// at another end point, or after `limit` pixels (then the branch is long).
std::optional<Branch> TraceEndBranch(const PaddedBinary& img, size_t start, int limit) {
  const std::ptrdiff_t s = static_cast<std::ptrdiff_t>(img.Stride());
  const std::ptrdiff_t offsets[8] = {-s - 1, -s, -s + 1, -1, 1, s - 1, s, s + 1};
  Branch branch;
  size_t prev = start, cur = start;
  branch.pixels.push_back(start);
  for (;;) {
    std::optional<size_t> next;
    int degree = 0;
    for (std::ptrdiff_t o : offsets) {
      const size_t q = static_cast<size_t>(static_cast<std::ptrdiff_t>(cur) + o);
      if (!img.data[q]) continue;
      ++degree;
      if (q != prev && !next) next = q;
    }
    if (cur != start) {
      if (degree >= 3) {  // reached a junction: it does not belong to the branch
        branch.pixels.pop_back();
        branch.junction = cur;
        return branch;
      }
      if (degree <= 1) return branch;  // the other end of a free line
    } else if (degree != 1) {
      return std::nullopt;  // not an end point (any more)
    }
    if (!next) return branch;
    if (static_cast<int>(branch.pixels.size()) >= limit) return std::nullopt;  // long: keep
    prev = cur;
    cur = *next;
    branch.pixels.push_back(cur);
  }
}

int DegreeOf(const PaddedBinary& img, size_t i) { return std::popcount(img.CodeOf(i)); }

}  // namespace

bool PruningWindowParams::IsValid(std::string* error) const {
  if (max_interior < 1 || max_interior > 8) {
    if (error) *error = "pruning window max_interior must lie in 1..8";
    return false;
  }
  return true;
}

bool SpurPruneParams::IsValid(std::string* error) const {
  auto fail = [error](const char* why) {
    if (error) *error = why;
    return false;
  };
  if (max_spur_length < 1 || max_spur_length > 10000)
    return fail("max_spur_length must lie in 1..10000 px");
  if (max_passes < 1 || max_passes > 100) return fail("spur max_passes must lie in 1..100");
  return true;
}

cv::Mat ApplyPruningWindows(const cv::Mat& skeleton, const PruningWindowParams& params) {
  RequireGrey8(skeleton, "ApplyPruningWindows", "skeleton");
  RequireValid(params, "ApplyPruningWindows");
  // Thesis 4.4, Figure 4.19 (interpretation in pruning.h): interiors by area.
  std::vector<std::pair<int, int>> interiors;  // (height, width)
  for (int h = 1; h <= params.max_interior; ++h)
    for (int w = 1; w <= params.max_interior; ++w) interiors.emplace_back(h, w);
  std::stable_sort(interiors.begin(), interiors.end(),
                   [](auto a, auto b) { return a.first * a.second < b.first * b.second; });
  cv::Mat img = (skeleton != 0);
  for (int y = 0; y < img.rows; ++y)
    for (int x = img.cols - 1; x >= 0; --x) {  // right to left, as in the thesis
      if (!img.at<unsigned char>(y, x)) continue;
      bool erased = false;
      for (const auto& [h, w] : interiors) {
        for (int offset = 0; offset < w && !erased; ++offset) {
          const int x0 = x - offset;  // S in the top row of the interior
          if (!RingIsBlack(img, x0, y, w, h)) continue;
          for (int yy = y; yy < y + h; ++yy)
            for (int xx = x0; xx < x0 + w; ++xx)
              if (IsSet(img, xx, yy)) img.at<unsigned char>(yy, xx) = 0;
          erased = true;
        }
        if (erased) break;
      }
    }
  return img;
}

cv::Mat PruneSpurs(const cv::Mat& skeleton, const SpurPruneParams& params) {
  RequireGrey8(skeleton, "PruneSpurs", "skeleton");
  RequireValid(params, "PruneSpurs");
  PaddedBinary img(skeleton);
  internal::PruneSpursInPlace(&img, params);
  return img.ToMat();
}

cv::Mat RemoveSmallComponents(const cv::Mat& binary, int min_pixels, const Cancellation& cancel) {
  RequireGrey8(binary, "RemoveSmallComponents", "binary image");
  if (min_pixels < 1) throw std::invalid_argument("RemoveSmallComponents: min_pixels must be >= 1");
  PaddedBinary img(binary);
  cancel.ThrowIfRequested("the small components");
  internal::RemoveSmallComponentsInPlace(&img, min_pixels, cancel);
  cancel.ThrowIfRequested("the small components");
  return img.ToMat();
}

namespace internal {

// Passes of tracing end branches and removing the short ones, shortest first.
void PruneSpursInPlace(PaddedBinary* img, const SpurPruneParams& params) {
  for (int pass = 0; pass < params.max_passes; ++pass) {
    std::vector<Branch> spurs;
    for (size_t i : img->SetIndices()) {
      if (DegreeOf(*img, i) != 1) continue;
      std::optional<Branch> b = TraceEndBranch(*img, i, params.max_spur_length);
      if (!b || static_cast<int>(b->pixels.size()) >= params.max_spur_length) continue;
      if (!b->junction && params.keep_free_ends) continue;
      spurs.push_back(std::move(*b));
    }
    if (spurs.empty()) break;
    std::stable_sort(spurs.begin(), spurs.end(), [](const Branch& a, const Branch& b) {
      return a.pixels.size() < b.pixels.size();
    });
    bool changed = false;
    for (const Branch& b : spurs) {
      // Re-check against the deletions made so far: the branch must be intact
      // and its junction still a junction, else it has become part of a line.
      if (!std::all_of(b.pixels.begin(), b.pixels.end(), [&](size_t i) { return img->data[i]; }))
        continue;
      if (b.junction && (!img->data[*b.junction] || DegreeOf(*img, *b.junction) < 3)) continue;
      for (size_t i : b.pixels) img->data[i] = 0;
      changed = true;
    }
    MakeOnePixelWideInPlace(img, TJunctionShape::kCentreKept);
    if (!changed) break;
  }
}

// 8-connected flood fill of each component from its first pixel in raster order.
void RemoveSmallComponentsInPlace(PaddedBinary* img, int min_pixels, const Cancellation& cancel) {
  if (min_pixels <= 1) return;
  const std::ptrdiff_t s = static_cast<std::ptrdiff_t>(img->Stride());
  const std::ptrdiff_t offsets[8] = {-s - 1, -s, -s + 1, -1, 1, s - 1, s, s + 1};
  // Flood fill each 8-connected component, marking its pixels 2; a small
  // one is erased, a large one restored to 1 afterwards.
  std::vector<size_t> component, stack, kept;
  int components = 0;
  for (size_t start : img->SetIndices()) {
    if (img->data[start] != 1) continue;
    if (++components % 4096 == 0) cancel.ThrowIfRequested("the small components");
    component.clear();
    stack.assign(1, start);
    img->data[start] = 2;
    while (!stack.empty()) {
      const size_t i = stack.back();
      stack.pop_back();
      component.push_back(i);
      for (std::ptrdiff_t o : offsets) {
        const size_t q = static_cast<size_t>(static_cast<std::ptrdiff_t>(i) + o);
        if (img->data[q] != 1) continue;
        img->data[q] = 2;
        stack.push_back(q);
      }
    }
    if (static_cast<int>(component.size()) < min_pixels)
      for (size_t i : component) img->data[i] = 0;
    else
      kept.insert(kept.end(), component.begin(), component.end());
  }
  for (size_t i : kept) img->data[i] = 1;
}

}  // namespace internal

}  // namespace bsls::extraction
