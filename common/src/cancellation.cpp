#include "bsls/common/cancellation.h"

#include <string>

namespace bsls {

void Cancellation::ThrowIfRequested(std::string_view where) const {
  if (Requested()) throw Cancelled("cancelled during " + std::string(where));
}

}  // namespace bsls
