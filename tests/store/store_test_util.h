// Shared fixtures of the capture store tests: a temporary directory that is
// removed afterwards, seeded random frames and requests, and the check that
// a reopened store lost nothing.
#ifndef BSLS_TESTS_STORE_STORE_TEST_UTIL_H_
#define BSLS_TESTS_STORE_STORE_TEST_UTIL_H_

#include <gtest/gtest.h>
#include <unistd.h>

#include <chrono>
#include <cstdint>
#include <filesystem>
#include <random>
#include <string>

#include "bsls/store/capture_store.h"

namespace bsls::store::testing {

// A fresh directory under TMPDIR (or /tmp), removed with its contents.
class TempDir {
 public:
  TempDir() {
    const char* base = std::getenv("TMPDIR");
    std::string pattern = std::string(base ? base : "/tmp") + "/bsls-store-XXXXXX";
    path_ = ::mkdtemp(pattern.data()) ? pattern : std::string();
  }
  ~TempDir() {
    std::error_code ignored;
    if (!path_.empty()) std::filesystem::remove_all(path_, ignored);
  }
  const std::string& path() const { return path_; }

 private:
  std::string path_;
};

// Opens a store; a failed test (and nullptr) when it cannot be opened.
inline std::unique_ptr<CaptureStore> OpenStore(const CaptureStoreOptions& options) {
  auto store = CaptureStore::Open(options);
  EXPECT_TRUE(store.ok()) << store.status().ToString();
  return store.ok() ? std::move(*store) : nullptr;
}

// A frame of seeded random pixels; stride may exceed width.
inline framestore::GreyFrame RandomFrame(std::mt19937& rng, framestore::Camera camera,
                                         int width = 64, int height = 48, int stride = 0) {
  framestore::GreyFrame frame;
  frame.width = width;
  frame.height = height;
  frame.stride = stride == 0 ? width : stride;
  frame.pixels.resize(static_cast<std::size_t>(frame.stride) * height);
  for (auto& pixel : frame.pixels) pixel = static_cast<std::uint8_t>(rng());
  frame.camera = camera;
  frame.gain = 128;
  frame.sequence = rng() % 1000;
  const auto now = std::chrono::steady_clock::now();
  frame.timestamps.requested = now - std::chrono::milliseconds(50);
  frame.timestamps.exposed = now - std::chrono::milliseconds(30);
  frame.timestamps.delivered = now;
  frame.timestamps.wall = std::chrono::system_clock::now();
  return frame;
}

// A two-frame (left and right) request of the given session and patient.
inline CaptureRequest RandomRequest(std::mt19937& rng, const std::string& session = "s1",
                                    const std::string& patient = "p1", int width = 64,
                                    int height = 48) {
  CaptureRequest request;
  request.session_id = session;
  request.patient_reference = patient;
  request.side = Side::kBoth;
  request.slide = 2;
  request.software_version = "bsls 0.1.0-test";
  request.requested_by = OperatorIdentity{1000, "operator"};
  request.frames.push_back(RandomFrame(rng, framestore::Camera::kLeft, width, height));
  request.frames.push_back(RandomFrame(rng, framestore::Camera::kRight, width, height));
  return request;
}

// Options for a store at `root` with no free-space reserve (tests run on
// whatever disk TMPDIR is).
inline CaptureStoreOptions TestOptions(const std::string& root) {
  CaptureStoreOptions options;
  options.root = root;
  options.free_space_reserve_bytes = 0;
  return options;
}

}  // namespace bsls::store::testing

#endif  // BSLS_TESTS_STORE_STORE_TEST_UTIL_H_
