#include "bsls/common/atomic_file.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "bsls/common/errors.h"

namespace bsls {
namespace {

namespace fs = std::filesystem;

std::string Contents(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

fs::path FreshDir(const std::string& name) {
  const fs::path dir = fs::path(::testing::TempDir()) / name;
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

TEST(AtomicFile, WritesAndReplacesAWholeFileLeavingNoTemporary) {
  const fs::path dir = FreshDir("atomic_file_replace");
  const fs::path target = dir / "out.bin";
  WriteFileAtomically(target.string(), std::string("first\0bytes", 11));
  EXPECT_EQ(Contents(target), std::string("first\0bytes", 11));
  WriteFileAtomically(target.string(), "second");
  EXPECT_EQ(Contents(target), "second");
  WriteFileAtomically(target.string(), "");
  EXPECT_EQ(Contents(target), "");
  EXPECT_EQ(std::distance(fs::directory_iterator(dir), fs::directory_iterator()), 1);
}

TEST(AtomicFile, AFailedWriteNamesTheFileAndLeavesTheOldOne) {
  const fs::path dir = FreshDir("atomic_file_fail");
  try {
    WriteFileAtomically((dir / "missing" / "out.bin").string(), "bytes");
    FAIL() << "no error";
  } catch (const OutputError& e) {
    EXPECT_NE(std::string(e.what()).find("missing/out.bin"), std::string::npos) << e.what();
  }
  // Renaming over a folder fails after the temporary file was written: the
  // folder stays and the temporary file is removed.
  fs::create_directories(dir / "taken");
  EXPECT_THROW(WriteFileAtomically((dir / "taken").string(), "bytes"), OutputError);
  EXPECT_TRUE(fs::is_directory(dir / "taken"));
  EXPECT_EQ(std::distance(fs::directory_iterator(dir), fs::directory_iterator()), 1);
}

}  // namespace
}  // namespace bsls
