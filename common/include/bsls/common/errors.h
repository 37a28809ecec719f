// The exceptions of the layers that report errors by throwing (processing,
// the processing service, the CLI): a file or other input that cannot be
// used, and an output that could not be written. what() names the file (or
// the input) and the reason; callers add no context of their own.
//
// The daemon's layers report errors as values instead (status.h).
#ifndef BSLS_COMMON_ERRORS_H_
#define BSLS_COMMON_ERRORS_H_

#include <stdexcept>

namespace bsls {

// An input file that cannot be used; what() names the file and the reason.
class InputError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// An output file that could not be written; what() names the file and the reason.
class OutputError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

}  // namespace bsls

#endif  // BSLS_COMMON_ERRORS_H_
