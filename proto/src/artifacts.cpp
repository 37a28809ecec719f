#include "bsls/rpc/artifacts.h"

#include <algorithm>

#include "bsls/common/sha256.h"

namespace bsls::rpc {

bool EmitArtifact(const std::string& name, const std::string& media_type, std::string_view bytes,
                  const std::function<bool(const v1::WorkEvent&)>& emit, std::size_t chunk_bytes) {
  const std::string sha256 = Sha256Hex(bytes);
  std::size_t offset = 0;
  do {
    const std::size_t n = std::min(chunk_bytes, bytes.size() - offset);
    v1::WorkEvent event;
    v1::Artifact* a = event.mutable_artifact();
    a->set_name(name);
    a->set_media_type(media_type);
    a->set_offset(offset);
    a->set_total_size(bytes.size());
    a->set_data(bytes.data() + offset, n);
    offset += n;
    a->set_last(offset == bytes.size());
    if (a->last()) a->set_sha256(sha256);
    if (!emit(event)) return false;
  } while (offset < bytes.size());
  return true;
}

ArtifactAssembler::ArtifactAssembler(std::uint64_t max_total_bytes)
    : max_total_bytes_(max_total_bytes) {}

void ArtifactAssembler::Add(const v1::Artifact& chunk) {
  const std::string& name = chunk.name();
  if (name.empty()) throw ArtifactError("an artifact chunk without a name");
  if (files_.count(name)) throw ArtifactError(name + ": sent twice");
  Partial& p = partial_[name];
  if (chunk.offset() == 0 && p.bytes.empty()) {
    p.media_type = chunk.media_type();
    p.total_size = chunk.total_size();
  }
  if (chunk.offset() != p.bytes.size())
    throw ArtifactError(name + ": a chunk at offset " + std::to_string(chunk.offset()) + " after " +
                        std::to_string(p.bytes.size()) + " bytes");
  if (chunk.total_size() != p.total_size || p.bytes.size() + chunk.data().size() > p.total_size)
    throw ArtifactError(name + ": more bytes than the " + std::to_string(p.total_size) +
                        " announced");
  received_ += chunk.data().size();
  if (received_ > max_total_bytes_)
    throw ArtifactError(name + ": the results exceed " + std::to_string(max_total_bytes_) +
                        " bytes");
  p.bytes += chunk.data();
  if (!chunk.last()) return;
  if (p.bytes.size() != p.total_size)
    throw ArtifactError(name + ": ended after " + std::to_string(p.bytes.size()) + " of " +
                        std::to_string(p.total_size) + " bytes");
  if (Sha256Hex(p.bytes) != chunk.sha256())
    throw ArtifactError(name + ": SHA-256 does not match (damaged in transit)");
  files_[name] = std::move(p.bytes);
  partial_.erase(name);
}

std::string ArtifactAssembler::Unfinished() const {
  std::string names;
  for (const auto& [name, p] : partial_) names += (names.empty() ? "" : ", ") + name;
  return names;
}

}  // namespace bsls::rpc
