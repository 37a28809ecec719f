// Writing a file so that a reader never sees it half-written (contracts
// section 5): the old file or the whole new one.
//
// Thread-safety: safe from any thread for different paths; concurrent
// writes to one path are not safe.
#ifndef BSLS_COMMON_ATOMIC_FILE_H_
#define BSLS_COMMON_ATOMIC_FILE_H_

#include <string>
#include <string_view>

namespace bsls {

// Writes bytes to `path` atomically: a temporary file in the same folder,
// fsync, rename over the target, fsync of the folder. Throws OutputError
// (errors.h) naming the file and the reason; on failure no temporary file
// is left and the old file, if any, is untouched.
void WriteFileAtomically(const std::string& path, std::string_view bytes);

}  // namespace bsls

#endif  // BSLS_COMMON_ATOMIC_FILE_H_
