// The one exception type of the joining stage.
#ifndef BSLS_JOINING_JOIN_ERROR_H_
#define BSLS_JOINING_JOIN_ERROR_H_

#include <stdexcept>
#include <string>

namespace bsls::joining {

// Two sides that cannot be joined. what() names the input ("left mesh",
// "right mesh", "parameters") and the reason; reason() classifies it.
class JoinError : public std::runtime_error {
 public:
  enum class Reason {
    kInvalidInput,      // invalid parameters, an empty or inconsistent mesh
    kNoReferenceLine,   // a side has no vertex on the reference line (or no labels)
    kFeaturesNotFound,  // the nose or the mouth is not on a side's reference line
    kNotConverged,      // ICP did not converge within its iteration cap, or degenerated
  };

  JoinError(Reason reason, const std::string& what) : std::runtime_error(what), reason_(reason) {}
  Reason reason() const { return reason_; }

 private:
  Reason reason_;
};

}  // namespace bsls::joining

#endif  // BSLS_JOINING_JOIN_ERROR_H_
