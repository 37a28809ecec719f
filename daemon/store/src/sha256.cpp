#include "bsls/store/sha256.h"

#include <openssl/evp.h>

#include <cassert>
#include <memory>

namespace bsls::store {

namespace {

struct DigestContextDeleter {
  void operator()(EVP_MD_CTX* context) const { EVP_MD_CTX_free(context); }
};

std::string Hex(const unsigned char* digest, unsigned int size) {
  constexpr char kHex[] = "0123456789abcdef";
  std::string text(2 * size, '0');
  for (unsigned int i = 0; i < size; ++i) {
    text[2 * i] = kHex[digest[i] >> 4];
    text[2 * i + 1] = kHex[digest[i] & 0xF];
  }
  return text;
}

// Feeds `rows` rows of `width` bytes, `stride` apart, into one digest.
std::string DigestRows(const std::uint8_t* data, std::size_t width, std::size_t stride,
                       std::size_t rows) {
  std::unique_ptr<EVP_MD_CTX, DigestContextDeleter> context(EVP_MD_CTX_new());
  // OpenSSL failing to allocate or to run SHA-256 leaves nothing to recover.
  bool ok = context && EVP_DigestInit_ex(context.get(), EVP_sha256(), nullptr) == 1;
  assert(ok);
  if (stride == width) {
    ok = ok && EVP_DigestUpdate(context.get(), data, width * rows) == 1;
  } else {
    for (std::size_t row = 0; ok && row < rows; ++row) {
      ok = EVP_DigestUpdate(context.get(), data + row * stride, width) == 1;
    }
  }
  unsigned char digest[EVP_MAX_MD_SIZE];
  unsigned int size = 0;
  ok = ok && EVP_DigestFinal_ex(context.get(), digest, &size) == 1;
  assert(ok && size == 32);
  (void)ok;
  return Hex(digest, size);
}

}  // namespace

std::string PixelSha256(const framestore::GreyFrame& frame) {
  assert(frame.width > 0 && frame.height > 0 && frame.stride >= frame.width);
  assert(frame.pixels.size() >= static_cast<std::size_t>(frame.stride) * frame.height);
  return DigestRows(frame.pixels.data(), static_cast<std::size_t>(frame.width),
                    static_cast<std::size_t>(frame.stride), static_cast<std::size_t>(frame.height));
}

std::string Sha256(const std::uint8_t* data, std::size_t size) {
  return DigestRows(data, size, size, 1);
}

}  // namespace bsls::store
