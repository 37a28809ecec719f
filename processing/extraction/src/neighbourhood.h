// 3x3 neighbourhoods of binary images, for thinning and pruning (not installed).
//
// Neighbour naming of thesis Figure 4.18 (p1 is the pixel itself):
//     p9 p2 p3
//     p8 p1 p4
//     p7 p6 p5
#ifndef BSLS_EXTRACTION_SRC_NEIGHBOURHOOD_H_
#define BSLS_EXTRACTION_SRC_NEIGHBOURHOOD_H_

#include <array>
#include <bit>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <opencv2/core.hpp>
#include <vector>

namespace bsls::extraction::internal {

// The eight neighbours of a pixel, 0 or 1 each.
struct Neighbours {
  int p2 = 0, p3 = 0, p4 = 0, p5 = 0, p6 = 0, p7 = 0, p8 = 0, p9 = 0;

  // N(p1) of thesis eq. 4.19: the number of set neighbours.
  int Count() const { return p2 + p3 + p4 + p5 + p6 + p7 + p8 + p9; }

  // S(p1) of thesis eq. 4.18 (b): 0 -> 1 transitions in p2, p3, ..., p9, p2.
  int Transitions() const {
    const int s[9] = {p2, p3, p4, p5, p6, p7, p8, p9, p2};
    int n = 0;
    for (int k = 0; k < 8; ++k) n += (!s[k] && s[k + 1]) ? 1 : 0;
    return n;
  }

  // Yokoi's 8-connectivity number: the number of 8-connected foreground
  // components the pixel joins (for a pixel with a background 4-neighbour).
  // The pixel is 8-simple (deletable without changing the topology of an
  // 8-foreground / 4-background image) exactly when this is 1.
  int ConnectivityNumber8() const {
    // x1..x8 = E, NE, N, NW, W, SW, S, SE; complemented.
    const int c[9] = {1 - p4, 1 - p3, 1 - p2, 1 - p9, 1 - p8, 1 - p7, 1 - p6, 1 - p5, 1 - p4};
    int n = 0;
    for (int k = 0; k < 8; k += 2) n += c[k] - c[k] * c[k + 1] * c[k + 2];
    return n;
  }
};

// The 8-bit code of a neighbourhood: bit 0 = p2, bit 1 = p3, ..., bit 7 = p9
// (clockwise from north).
inline Neighbours FromCode(unsigned code) {
  Neighbours n;
  n.p2 = code & 1;
  n.p3 = (code >> 1) & 1;
  n.p4 = (code >> 2) & 1;
  n.p5 = (code >> 3) & 1;
  n.p6 = (code >> 4) & 1;
  n.p7 = (code >> 5) & 1;
  n.p8 = (code >> 6) & 1;
  n.p9 = (code >> 7) & 1;
  return n;
}

// A yes/no property of a neighbourhood tabulated for all 256 codes.
using CodeTable = std::array<bool, 256>;

// The table of predicate(FromCode(code)).
template <typename Predicate>
CodeTable MakeCodeTable(Predicate predicate) {
  CodeTable table{};
  for (unsigned code = 0; code < 256; ++code) table[code] = predicate(FromCode(code));
  return table;
}

// A binary image copied into a 0/1 buffer with a one-pixel black border, so
// that every pixel of the image has eight neighbours in the buffer.
class PaddedBinary {
 public:
  explicit PaddedBinary(const cv::Mat& binary)  // CV_8UC1, non-zero = set
      : rows_(binary.rows),
        cols_(binary.cols),
        stride_(static_cast<size_t>(binary.cols) + 2),
        data(stride_ * (static_cast<size_t>(binary.rows) + 2), 0) {
    cv::Mat inner = Inner();
    cv::min(binary, 1, inner);  // 0 / 1
  }

  size_t Index(int x, int y) const {
    return (static_cast<size_t>(y) + 1) * stride_ + static_cast<size_t>(x) + 1;
  }
  int X(size_t i) const { return static_cast<int>(i % stride_) - 1; }
  int Y(size_t i) const { return static_cast<int>(i / stride_) - 1; }
  size_t Stride() const { return stride_; }
  int Rows() const { return rows_; }
  int Cols() const { return cols_; }

  Neighbours NeighboursOf(size_t i) const { return FromCode(CodeOf(i)); }

  // The neighbourhood code of the pixel at index i (see FromCode).
  unsigned CodeOf(size_t i) const {
    const std::uint8_t* c = data.data() + i;
    const std::uint8_t* up = c - stride_;
    const std::uint8_t* down = c + stride_;
    return up[0] | (up[1] << 1) | (c[1] << 2) | (down[1] << 3) | (down[0] << 4) | (down[-1] << 5) |
           (c[-1] << 6) | (up[-1] << 7);
  }

  // Buffer indices of the set pixels, in raster order.
  std::vector<size_t> SetIndices() const {
    std::vector<size_t> out;
    out.reserve(count_hint_);  // stages delete pixels: the last count is a good bound
    const std::uint8_t* d = data.data();
    const size_t begin = stride_, end = data.size() - stride_;  // the image's rows
    size_t i = begin;
    for (; i + 8 <= end; i += 8) {                     // eight pixels at a time
      if (i + 32 <= end && ((i - begin) & 31) == 0) {  // skip empty 32-pixel runs
        std::uint64_t words[4];
        std::memcpy(words, d + i, 32);
        if (!(words[0] | words[1] | words[2] | words[3])) {
          i += 24;  // and 8 by the loop
          continue;
        }
      }
      std::uint64_t word;
      std::memcpy(&word, d + i, 8);
      // The top bit of every non-zero byte (byte k is bits 8k .. 8k + 7).
      static_assert(std::endian::native == std::endian::little);
      constexpr std::uint64_t kLow7 = 0x7F7F7F7F7F7F7F7Full;
      std::uint64_t set = (((word & kLow7) + kLow7) | word) & ~kLow7;
      while (set) {
        out.push_back(i + static_cast<size_t>(std::countr_zero(set) / 8));
        set &= set - 1;
      }
    }
    for (; i < end; ++i)
      if (d[i]) out.push_back(i);
    count_hint_ = out.size();
    return out;  // the border is always 0, so only image pixels are listed
  }

  // The image as CV_8UC1, 0 / 255.
  cv::Mat ToMat() const {
    cv::Mat out;
    cv::compare(Inner(), 0, out, cv::CMP_NE);
    return out;
  }

  // CV_8UC1, 255 where the buffer holds `value`, else 0 (for algorithms
  // that mark pixels with values other than 0 / 1).
  cv::Mat ToMatWhere(std::uint8_t value) const {
    cv::Mat out;
    cv::compare(Inner(), value, out, cv::CMP_EQ);
    return out;
  }

 private:
  // The image part of the buffer as a CV_8UC1 header (no copy).
  cv::Mat Inner() const {
    const cv::Mat all(rows_ + 2, cols_ + 2, CV_8UC1, const_cast<std::uint8_t*>(data.data()));
    return all(cv::Rect(1, 1, cols_, rows_));
  }

  int rows_;
  int cols_;
  size_t stride_;
  mutable size_t count_hint_ = 0;  // set pixels at the last SetIndices

 public:
  std::vector<std::uint8_t> data;  // 0 / 1, (rows + 2) x (cols + 2)
};

}  // namespace bsls::extraction::internal

#endif  // BSLS_EXTRACTION_SRC_NEIGHBOURHOOD_H_
