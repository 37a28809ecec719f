// Shared fixture of the framestore tests: an ISA card emulator fed with
// fixed pictures per video input (the simulator's face renders or synthetic
// patterns), and an IsaFramestore driving it.
#ifndef BSLS_TESTS_FRAMESTORE_EMULATED_CARD_H_
#define BSLS_TESTS_FRAMESTORE_EMULATED_CARD_H_

#include <array>
#include <functional>
#include <memory>

#include "bsls/framestore/isa_card_emulator.h"
#include "bsls/framestore/isa_framestore.h"

namespace bsls::framestore::testing {

// A 512 x 512 picture with grey level f(x, y) at column x, row y.
inline std::shared_ptr<const VideoFrame> MakePicture(
    const std::function<std::uint8_t(int x, int y)>& f) {
  auto picture = std::make_shared<VideoFrame>();
  picture->pixels.resize(static_cast<std::size_t>(picture->width) * picture->height);
  for (int y = 0; y < picture->height; ++y) {
    for (int x = 0; x < picture->width; ++x) picture->pixels[y * picture->width + x] = f(x, y);
  }
  return picture;
}

// Pictures on the card's three video inputs; nullptr = no camera there.
struct Cameras {
  std::array<std::shared_ptr<const VideoFrame>, isa::kVideoInputs> inputs;

  VideoSource Source() const {
    auto inputs_copy = inputs;
    return [inputs_copy](int input, std::int64_t) -> std::shared_ptr<const VideoFrame> {
      if (input < 0 || input >= isa::kVideoInputs) return nullptr;
      return inputs_copy[input];
    };
  }
};

// Driver timeouts short enough for fault tests, long enough for a loaded CI
// machine (the emulator is bus-clocked: a grab costs ~1.8 million accesses).
inline IsaFramestoreParams FastParams() {
  IsaFramestoreParams params;
  params.idle_timeout = std::chrono::milliseconds(2000);
  params.resync_quiet = std::chrono::milliseconds(50);
  params.digitise_timeout = std::chrono::milliseconds(150);
  params.pair_timeout = std::chrono::milliseconds(20);
  params.download_timeout = std::chrono::milliseconds(10000);
  return params;
}

// The emulator (borrowed from the driver that owns it) and the driver.
struct EmulatedCard {
  IsaCardEmulator* card = nullptr;
  std::unique_ptr<IsaFramestore> framestore;
  Status open_status;
};

inline std::unique_ptr<IsaCardEmulator> MakeEmulator(const Cameras& cameras,
                                                     const IsaCardEmulatorParams& params = {}) {
  return std::make_unique<IsaCardEmulator>(params, cameras.Source());
}

// Opens an IsaFramestore over a fresh emulator; open_status says how it went.
inline EmulatedCard OpenEmulatedCard(const Cameras& cameras,
                                     const IsaFramestoreParams& params = FastParams(),
                                     const EmulatorFaults& faults = {},
                                     const IsaCardEmulatorParams& card_params = {}) {
  EmulatedCard result;
  auto emulator = MakeEmulator(cameras, card_params);
  emulator->SetFaults(faults);
  result.card = emulator.get();
  auto opened = IsaFramestore::Open(std::move(emulator), params);
  if (opened.ok()) {
    result.framestore = std::move(opened).value();
  } else {
    result.open_status = opened.status();
    result.card = nullptr;  // died with the failed driver
  }
  return result;
}

}  // namespace bsls::framestore::testing

#endif  // BSLS_TESTS_FRAMESTORE_EMULATED_CARD_H_
