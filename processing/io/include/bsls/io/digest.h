// Content digests for files and frames: what the calibration file records of
// its manifest and what the frame store records of each frame's pixels.
#ifndef BSLS_IO_DIGEST_H_
#define BSLS_IO_DIGEST_H_

#include <string>
#include <string_view>

namespace bsls::io {

// SHA-256 of `bytes` as 64 lower-case hex digits (OpenSSL's EVP interface).
std::string Sha256Hex(std::string_view bytes);

// SHA-256 of a whole file's bytes. Throws InputError naming the file when it
// cannot be read.
std::string Sha256OfFile(const std::string& path);

}  // namespace bsls::io

#endif  // BSLS_IO_DIGEST_H_
