// The lowest layer of the slide controller: a few GPIO lines of one chip.
// LibgpiodLines drives a real chip through libgpiod (Debian's v1.6 API);
// EmulatedSlideChanger (emulated_slide_changer.h) models the projector's
// slide mechanism at the same line level, so the SlideController's real
// code runs on machines without GPIO.
//
// Values are the PHYSICAL line levels (0 low, 1 high); the controller applies
// its configuration's active-low setting.
//
// Thread-safety: implementations are safe from several threads.
#ifndef BSLS_SLIDES_GPIO_LINES_H_
#define BSLS_SLIDES_GPIO_LINES_H_

#include <chrono>
#include <memory>
#include <string>

#include "bsls/common/status.h"

namespace bsls::slides {

using Clock = std::chrono::steady_clock;

class GpioLines {
 public:
  virtual ~GpioLines() = default;

  // Claims line `offset` as an output driven to `initial`.
  virtual Status RequestOutput(unsigned offset, int initial) = 0;
  // Claims line `offset` as an input (with edge events where the chip has them).
  virtual Status RequestInput(unsigned offset) = 0;
  // Drives output `offset` to `value` (0 or 1).
  virtual Status Set(unsigned offset, int value) = 0;
  // Reads line `offset`.
  virtual Result<int> Get(unsigned offset) = 0;
  // Waits until input `offset` reads `value`: true when it did before
  // `deadline`, false when the deadline passed first.
  virtual Result<bool> WaitFor(unsigned offset, int value, Clock::time_point deadline) = 0;
  // The chip for messages: "gpiochip0 [bsls-slides]".
  virtual std::string Describe() const = 0;
};

// Opens GPIO chip `chip` (a name such as "gpiochip0", a label, or a path in
// /dev) through libgpiod. kUnavailable naming the chip when it does not
// exist, kPermissionDenied naming the udev rule when it may not be opened.
Result<std::unique_ptr<GpioLines>> OpenLibgpiodChip(const std::string& chip);

}  // namespace bsls::slides

#endif  // BSLS_SLIDES_GPIO_LINES_H_
