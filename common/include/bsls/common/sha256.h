// SHA-256 (OpenSSL's EVP interface), written as 64 lower-case hex digits:
// what the calibration file records of its manifest, what the capture store
// records of each frame's pixels and result files, what an artifact chunk
// carries. The project's one implementation.
//
// Errors: DigestError when OpenSSL cannot allocate or run the digest (out of
// memory, a broken provider configuration), never an assert: no input makes
// a digest fail. Sha256OfFile throws InputError (errors.h) naming the file.
//
// Thread-safety: the functions are pure (and the file); a Sha256 object is
// used by one thread at a time.
#ifndef BSLS_COMMON_SHA256_H_
#define BSLS_COMMON_SHA256_H_

#include <memory>
#include <stdexcept>
#include <string>
#include <string_view>

struct evp_md_ctx_st;

namespace bsls {

// OpenSSL could not compute a digest; what() names the step that failed.
class DigestError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// A SHA-256 digest fed piece by piece (e.g. a frame's rows without their
// stride padding). Throws DigestError.
class Sha256 {
 public:
  // An empty digest, ready for Update.
  Sha256();
  // Frees OpenSSL's context.
  ~Sha256();
  Sha256(const Sha256&) = delete;
  Sha256& operator=(const Sha256&) = delete;

  // Adds `size` bytes at `data` to the digest.
  void Update(const void* data, std::size_t size);
  // Adds `bytes` to the digest.
  void Update(std::string_view bytes) { Update(bytes.data(), bytes.size()); }
  // The digest of everything added, as 64 hex digits; the object is spent
  // after (a further Update or HexDigest throws DigestError).
  std::string HexDigest();

 private:
  struct Free {
    void operator()(evp_md_ctx_st* context) const;
  };
  std::unique_ptr<evp_md_ctx_st, Free> context_;
};

// SHA-256 of `bytes` as 64 lower-case hex digits. Throws DigestError.
std::string Sha256Hex(std::string_view bytes);

// SHA-256 of a whole file's bytes. Throws InputError naming the file when it
// cannot be read, DigestError.
std::string Sha256OfFile(const std::string& path);

}  // namespace bsls

#endif  // BSLS_COMMON_SHA256_H_
