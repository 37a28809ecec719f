// The one error type of camera and projector calibration: the input cannot
// give a calibration, and why. Thrown only for input or parameters, never for
// our own bugs.
#ifndef BSLS_CALIBRATION_CALIBRATION_ERROR_H_
#define BSLS_CALIBRATION_CALIBRATION_ERROR_H_

#include <stdexcept>
#include <string>
#include <string_view>

namespace bsls::calibration {

enum class CalibrationErrorReason {
  kInvalidParams,    // a Params struct failed IsValid
  kInvalidInput,     // non-finite coordinates, bad image size, mismatched sizes
  kTooFewPoints,     // fewer correspondences than the model needs
  kCoplanar,         // all points in one plane: the non-coplanar methods cannot work
  kDegenerate,       // the linear solve or the refinement has no unique solution
  kUnreadableInput,  // a listed file is missing or cannot be read as an image
  kNotFound,         // the target, the pattern or the cross is not (fully) found in a view
  kNotConverged,     // an iterative refinement stopped before converging
  kCancelled,        // the caller stopped it (CalibrationProgress returned false)
};

// Returns "invalid params", "invalid input", "too few points", "coplanar",
// "degenerate", "unreadable input", "not found", "not converged" or "cancelled".
constexpr std::string_view ToString(CalibrationErrorReason reason) {
  switch (reason) {
    case CalibrationErrorReason::kInvalidParams:
      return "invalid params";
    case CalibrationErrorReason::kInvalidInput:
      return "invalid input";
    case CalibrationErrorReason::kTooFewPoints:
      return "too few points";
    case CalibrationErrorReason::kCoplanar:
      return "coplanar";
    case CalibrationErrorReason::kDegenerate:
      return "degenerate";
    case CalibrationErrorReason::kUnreadableInput:
      return "unreadable input";
    case CalibrationErrorReason::kCancelled:
      return "cancelled";
    case CalibrationErrorReason::kNotFound:
      return "not found";
    case CalibrationErrorReason::kNotConverged:
      return "not converged";
  }
  return "unknown";
}

// what() is a complete sentence naming the stage and the reason, e.g.
// "camera calibration: all 64 points lie in one plane ...".
class CalibrationError : public std::runtime_error {
 public:
  // Carries the reason code and the full message.
  CalibrationError(CalibrationErrorReason reason, const std::string& message)
      : std::runtime_error(message), reason_(reason) {}

  // Why the calibration failed, for callers that map errors to codes.
  CalibrationErrorReason reason() const { return reason_; }

 private:
  CalibrationErrorReason reason_;
};

}  // namespace bsls::calibration

#endif  // BSLS_CALIBRATION_CALIBRATION_ERROR_H_
