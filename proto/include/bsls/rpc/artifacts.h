// Output files of the processing service's work calls as Artifact chunks
// (bsls/v1/processing.proto): the service cuts each file into chunks of at
// most kArtifactChunkBytes, the client puts them back together and checks
// their order, size and SHA-256 before it trusts a byte.
//
// Thread-safety: EmitArtifact is pure; an ArtifactAssembler is used by one
// thread at a time.
#ifndef BSLS_RPC_ARTIFACTS_H_
#define BSLS_RPC_ARTIFACTS_H_

#include <cstdint>
#include <functional>
#include <map>
#include <stdexcept>
#include <string>
#include <string_view>

#include "bsls/v1/processing.pb.h"

namespace bsls::rpc {

inline constexpr std::size_t kArtifactChunkBytes = 1u << 20;

// Sends `bytes` as the artifact `name` through `emit`, one WorkEvent per
// chunk (an empty file is one empty last chunk). Stops and returns false as
// soon as `emit` does (the caller went away).
bool EmitArtifact(const std::string& name, const std::string& media_type, std::string_view bytes,
                  const std::function<bool(const v1::WorkEvent&)>& emit,
                  std::size_t chunk_bytes = kArtifactChunkBytes);

// Chunks that do not make a file: out of order, beyond the announced size,
// a hash that does not match, more bytes than the assembler accepts.
class ArtifactError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

class ArtifactAssembler {
 public:
  // Accepts at most `max_total_bytes` over all artifacts.
  explicit ArtifactAssembler(std::uint64_t max_total_bytes = std::uint64_t{2} << 30);

  // Adds one chunk; throws ArtifactError naming the artifact and the reason.
  void Add(const v1::Artifact& chunk);
  // The artifacts received whole (hash checked), by name.
  const std::map<std::string, std::string>& files() const { return files_; }
  // Names of artifacts begun but not finished (empty when all are whole).
  std::string Unfinished() const;

 private:
  struct Partial {
    std::string media_type;
    std::uint64_t total_size = 0;
    std::string bytes;
  };
  std::uint64_t max_total_bytes_;
  std::uint64_t received_ = 0;
  std::map<std::string, Partial> partial_;
  std::map<std::string, std::string> files_;
};

}  // namespace bsls::rpc

#endif  // BSLS_RPC_ARTIFACTS_H_
