#include "bsls/common/sha256.h"

#include <openssl/err.h>
#include <openssl/evp.h>

#include <array>
#include <cerrno>
#include <cstring>
#include <fstream>

#include "bsls/common/errors.h"

namespace bsls {
namespace {

// `step` and OpenSSL's reason for its last error, if it left one.
[[noreturn]] void Fail(const std::string& step) {
  const unsigned long code = ERR_get_error();
  ERR_clear_error();
  std::array<char, 256> reason{};
  if (code != 0) ERR_error_string_n(code, reason.data(), reason.size());
  throw DigestError("SHA-256: " + step + " failed" +
                    (code != 0 ? std::string(": ") + reason.data() : std::string()));
}

}  // namespace

void Sha256::Free::operator()(evp_md_ctx_st* context) const { EVP_MD_CTX_free(context); }

Sha256::Sha256() : context_(EVP_MD_CTX_new()) {
  if (!context_) Fail("EVP_MD_CTX_new");
  if (EVP_DigestInit_ex(context_.get(), EVP_sha256(), nullptr) != 1) Fail("EVP_DigestInit_ex");
}

Sha256::~Sha256() = default;

void Sha256::Update(const void* data, std::size_t size) {
  if (!context_) throw DigestError("SHA-256: Update after HexDigest");
  if (size > 0 && EVP_DigestUpdate(context_.get(), data, size) != 1) Fail("EVP_DigestUpdate");
}

std::string Sha256::HexDigest() {
  if (!context_) throw DigestError("SHA-256: HexDigest called twice");
  std::array<unsigned char, EVP_MAX_MD_SIZE> md{};
  unsigned int length = 0;
  if (EVP_DigestFinal_ex(context_.get(), md.data(), &length) != 1) Fail("EVP_DigestFinal_ex");
  context_.reset();
  static constexpr char kHex[] = "0123456789abcdef";
  std::string out;
  out.reserve(2 * length);
  for (unsigned int i = 0; i < length; ++i) {
    out.push_back(kHex[md[i] >> 4]);
    out.push_back(kHex[md[i] & 15]);
  }
  return out;
}

std::string Sha256Hex(std::string_view bytes) {
  Sha256 digest;
  digest.Update(bytes);
  return digest.HexDigest();
}

std::string Sha256OfFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path + ": cannot open: " + std::strerror(errno));
  Sha256 digest;
  std::array<char, 1 << 16> buffer{};
  while (in) {
    in.read(buffer.data(), buffer.size());
    digest.Update(buffer.data(), static_cast<std::size_t>(in.gcount()));
  }
  if (in.bad()) throw InputError(path + ": read failed");
  return digest.HexDigest();
}

}  // namespace bsls
