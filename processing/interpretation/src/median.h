// Private to bsls::interpretation: the median of row-spacing samples, which
// judges the steps along lines in both labellings (labelling.cpp,
// track_labelling.cpp).
#ifndef BSLS_INTERPRETATION_SRC_MEDIAN_H_
#define BSLS_INTERPRETATION_SRC_MEDIAN_H_

#include <algorithm>
#include <vector>

namespace bsls::interpretation::internal {

// The median of `v` (the upper middle one of an even count); 0 when empty.
inline double Median(std::vector<double> v) {
  if (v.empty()) return 0.0;
  std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
  return v[v.size() / 2];
}

}  // namespace bsls::interpretation::internal

#endif  // BSLS_INTERPRETATION_SRC_MEDIAN_H_
