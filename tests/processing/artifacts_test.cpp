// Output files cut into checked chunks and put back together.
#include "bsls/rpc/artifacts.h"

#include <gtest/gtest.h>

#include <vector>

namespace bsls::rpc {
namespace {

std::vector<v1::Artifact> Chunks(const std::string& bytes, std::size_t chunk) {
  std::vector<v1::Artifact> out;
  EXPECT_TRUE(EmitArtifact(
      "a.bin", "application/octet-stream", bytes,
      [&](const v1::WorkEvent& e) {
        out.push_back(e.artifact());
        return true;
      },
      chunk));
  return out;
}

TEST(Artifacts, RoundTripInChunks) {
  std::string bytes(10000, '\0');
  for (size_t i = 0; i < bytes.size(); ++i) bytes[i] = static_cast<char>(i * 7);
  const auto chunks = Chunks(bytes, 999);
  EXPECT_EQ(chunks.size(), 11u);
  ArtifactAssembler assembler;
  for (const auto& c : chunks) assembler.Add(c);
  EXPECT_EQ(assembler.files().at("a.bin"), bytes);
  EXPECT_TRUE(assembler.Unfinished().empty());
  // An empty file is one last chunk.
  ArtifactAssembler empty;
  for (const auto& c : Chunks("", 10)) empty.Add(c);
  EXPECT_EQ(empty.files().at("a.bin"), "");
}

TEST(Artifacts, DamageIsDetected) {
  const std::string bytes(5000, 'x');
  auto chunks = Chunks(bytes, 1000);
  {  // a flipped byte
    auto damaged = chunks;
    (*damaged[2].mutable_data())[5] = 'y';
    ArtifactAssembler a;
    for (size_t i = 0; i + 1 < damaged.size(); ++i) a.Add(damaged[i]);
    EXPECT_THROW(a.Add(damaged.back()), ArtifactError);
  }
  {  // a lost chunk
    ArtifactAssembler a;
    a.Add(chunks[0]);
    EXPECT_THROW(a.Add(chunks[2]), ArtifactError);
  }
  {  // more than announced
    auto longer = chunks;
    longer.back().mutable_data()->append("zz");
    ArtifactAssembler a;
    for (size_t i = 0; i + 1 < longer.size(); ++i) a.Add(longer[i]);
    EXPECT_THROW(a.Add(longer.back()), ArtifactError);
  }
  {  // a stream that stops half-way
    ArtifactAssembler a;
    a.Add(chunks[0]);
    EXPECT_EQ(a.Unfinished(), "a.bin");
  }
  {  // beyond the client's cap
    ArtifactAssembler a(2500);
    a.Add(chunks[0]);
    a.Add(chunks[1]);
    EXPECT_THROW(a.Add(chunks[2]), ArtifactError);
  }
}

}  // namespace
}  // namespace bsls::rpc
