// SHA-256 of a frame's pixels, written as 64 lower-case hex digits. "The
// pixels" are the width x height grey levels row by row, top row first,
// WITHOUT stride padding: the same digest whatever the stride, and the
// digest of a stored PGM file's pixel block (sha256sum of the file's last
// width*height bytes). The digest itself is bsls::common's (sha256.h).
//
// The store reports errors as values: OpenSSL's failure (DigestError) comes
// back as kInternal, not as an exception.
//
// Thread-safety: pure functions.
#ifndef BSLS_STORE_SHA256_H_
#define BSLS_STORE_SHA256_H_

#include <string>
#include <string_view>

#include "bsls/common/status.h"
#include "bsls/framestore/framestore.h"

namespace bsls::store {

// The hex SHA-256 of `frame`'s width x height pixels (rows without padding).
// kInvalidArgument naming the sizes when the frame is not well-formed
// (positive sides, stride >= width, pixels.size() >= stride * height);
// kInternal when OpenSSL cannot compute a digest.
Result<std::string> PixelSha256(const framestore::GreyFrame& frame);

// The hex SHA-256 of `bytes` (a result file, a frame file's pixel block);
// kInternal when OpenSSL cannot compute a digest.
Result<std::string> BytesSha256(std::string_view bytes);

}  // namespace bsls::store

#endif  // BSLS_STORE_SHA256_H_
