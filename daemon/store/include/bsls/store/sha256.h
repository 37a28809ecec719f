// SHA-256 of a frame's pixels (OpenSSL EVP), written as 64 lower-case hex
// digits. "The pixels" are the width x height grey levels row by row, top
// row first, WITHOUT stride padding: the same digest whatever the stride,
// and the digest of a stored PGM file's pixel block (sha256sum of the file's
// last width*height bytes).
//
// Thread-safety: pure functions.
#ifndef BSLS_STORE_SHA256_H_
#define BSLS_STORE_SHA256_H_

#include <cstddef>
#include <cstdint>
#include <string>

#include "bsls/framestore/framestore.h"

namespace bsls::store {

// The hex SHA-256 of `frame`'s width x height pixels (rows without padding).
// The frame must be well-formed (pixels.size() >= stride * height).
std::string PixelSha256(const framestore::GreyFrame& frame);

// The hex SHA-256 of `size` bytes at `data`.
std::string Sha256(const std::uint8_t* data, std::size_t size);

}  // namespace bsls::store

#endif  // BSLS_STORE_SHA256_H_
