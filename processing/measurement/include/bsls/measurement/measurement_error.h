// The one exception type of the measurement stage.
#ifndef BSLS_MEASUREMENT_MEASUREMENT_ERROR_H_
#define BSLS_MEASUREMENT_MEASUREMENT_ERROR_H_

#include <stdexcept>
#include <string>

namespace bsls::measurement {

// A measurement that cannot be taken on the given input: a mesh without
// faces, a point outside the surface, a region with no surface in it, invalid
// parameters. what() names the input and the reason.
class MeasurementError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

}  // namespace bsls::measurement

#endif  // BSLS_MEASUREMENT_MEASUREMENT_ERROR_H_
