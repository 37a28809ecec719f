// 3x3 neighbourhoods of binary images, for thinning and pruning (not installed).
//
// Neighbour naming of thesis Figure 4.18 (p1 is the pixel itself):
//     p9 p2 p3
//     p8 p1 p4
//     p7 p6 p5
#ifndef BSLS_EXTRACTION_SRC_NEIGHBOURHOOD_H_
#define BSLS_EXTRACTION_SRC_NEIGHBOURHOOD_H_

#include <cstddef>
#include <cstdint>
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

// A binary image copied into a 0/1 buffer with a one-pixel black border, so
// that every pixel of the image has eight neighbours in the buffer.
class PaddedBinary {
 public:
  explicit PaddedBinary(const cv::Mat& binary)  // CV_8UC1, non-zero = set
      : rows_(binary.rows),
        cols_(binary.cols),
        stride_(static_cast<size_t>(binary.cols) + 2),
        data(stride_ * (static_cast<size_t>(binary.rows) + 2), 0) {
    for (int y = 0; y < rows_; ++y) {
      const unsigned char* row = binary.ptr<unsigned char>(y);
      for (int x = 0; x < cols_; ++x) data[Index(x, y)] = row[x] ? 1 : 0;
    }
  }

  size_t Index(int x, int y) const {
    return (static_cast<size_t>(y) + 1) * stride_ + static_cast<size_t>(x) + 1;
  }
  int X(size_t i) const { return static_cast<int>(i % stride_) - 1; }
  int Y(size_t i) const { return static_cast<int>(i / stride_) - 1; }
  size_t Stride() const { return stride_; }

  Neighbours NeighboursOf(size_t i) const {
    const std::uint8_t* c = data.data() + i;
    const std::uint8_t* up = c - stride_;
    const std::uint8_t* down = c + stride_;
    Neighbours n;
    n.p2 = up[0];
    n.p3 = up[1];
    n.p4 = c[1];
    n.p5 = down[1];
    n.p6 = down[0];
    n.p7 = down[-1];
    n.p8 = c[-1];
    n.p9 = up[-1];
    return n;
  }

  // Buffer indices of the set pixels, in raster order.
  std::vector<size_t> SetIndices() const {
    std::vector<size_t> out;
    for (int y = 0; y < rows_; ++y)
      for (int x = 0; x < cols_; ++x)
        if (data[Index(x, y)]) out.push_back(Index(x, y));
    return out;
  }

  // The image as CV_8UC1, 0 / 255.
  cv::Mat ToMat() const {
    cv::Mat out(rows_, cols_, CV_8UC1);
    for (int y = 0; y < rows_; ++y) {
      unsigned char* row = out.ptr<unsigned char>(y);
      for (int x = 0; x < cols_; ++x) row[x] = data[Index(x, y)] ? 255 : 0;
    }
    return out;
  }

 private:
  int rows_;
  int cols_;
  size_t stride_;

 public:
  std::vector<std::uint8_t> data;  // 0 / 1, (rows + 2) x (cols + 2)
};

}  // namespace bsls::extraction::internal

#endif  // BSLS_EXTRACTION_SRC_NEIGHBOURHOOD_H_
