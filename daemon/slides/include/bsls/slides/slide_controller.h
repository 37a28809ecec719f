// The projector's slide controller (thesis Figure 1.1, 2.4-2.6): three slides
// on a carousel -- 1 the reference cross (optic set-up, patient positioning),
// 2 the brick pattern for the left side, 3 for the right side -- plus the
// projector's focus motor and lamp, all on GPIO lines:
//
//   advance   output  a pulse moves the carousel (to the selected slide when
//                     select lines exist, else one position on)
//   select0/1 outputs optional: the binary number of the wanted slide
//   in_place  input   the mechanism confirms a slide is in the gate
//   lamp      output  projector lamp on/off
//   focus_in/out outputs one pulse per focus motor step
//
// Without select lines the controller counts advances from `initial_slide`
// (the carousel's position at power-on, which the operator sets).
//
// Thread-safety: every member is safe from several threads; commands are
// serialised (a second ChangeTo waits for the first).
#ifndef BSLS_SLIDES_SLIDE_CONTROLLER_H_
#define BSLS_SLIDES_SLIDE_CONTROLLER_H_

#include <chrono>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <string>

#include "bsls/slides/gpio_lines.h"

namespace bsls::slides {

inline constexpr int kSlides = 3;

struct SlideControllerConfig {
  std::string chip = "gpiochip0";  // libgpiod: name, label or /dev path
  unsigned advance_line = 0;
  std::optional<unsigned> select0_line;  // both or neither
  std::optional<unsigned> select1_line;
  unsigned in_place_line = 3;
  unsigned lamp_line = 4;
  unsigned focus_in_line = 5;
  unsigned focus_out_line = 6;
  bool active_low = false;                         // every line: logical 1 is the low level
  std::chrono::milliseconds pulse{50};             // advance pulse width
  std::chrono::milliseconds settle{20};            // in_place must drop within this after a pulse
  std::chrono::milliseconds change_timeout{5000};  // per slide change
  std::chrono::milliseconds focus_step{5};         // high and low time of one focus step
  int initial_slide = 1;                           // at power-on, without select lines
  // The emulated mechanism's travel time per position (slides.backend simulated).
  std::chrono::milliseconds emulated_travel{300};
};

// kInvalidArgument naming the first bad field (a line used twice, one select
// line without the other, times out of range, initial_slide outside 1..3).
Status Validate(const SlideControllerConfig& config);

// What the controller knows.
struct SlideState {
  int slide = 0;          // the slide last commanded (0: unknown)
  bool in_place = false;  // the mechanism confirmed it
  bool moving = false;    // a change is under way
  bool lamp_on = false;
  int focus_position = 0;  // focus steps from start-up (+ farther)
  std::string last_error;  // of the last command; empty when it succeeded
};

class SlideController {
 public:
  // Claims the lines (outputs idle, lamp off) and reads in_place. Fails with
  // the line layer's error naming the line; kInvalidArgument for a bad config.
  static Result<std::unique_ptr<SlideController>> Open(std::unique_ptr<GpioLines> lines,
                                                       const SlideControllerConfig& config);

  // A snapshot of the state.
  SlideState State() const;
  // Puts `slide` (1..3) in place and waits for the confirmation until
  // `deadline` (or the configured change timeout, whichever comes first):
  // kDeadlineExceeded "slide N not confirmed in place after X ms" otherwise.
  Status ChangeTo(int slide, Clock::time_point deadline);
  // Moves the focus motor by `steps` (sign: + farther), one pulse per step.
  Status Focus(int steps, Clock::time_point deadline);
  // Switches the lamp.
  Status SetLamp(bool on);
  // Called (outside the controller's lock) after every state change.
  void SetListener(std::function<void(const SlideState&)> listener);

 private:
  SlideController(std::unique_ptr<GpioLines> lines, const SlideControllerConfig& config);
  Status Drive(unsigned line, bool logical);
  Status Pulse(unsigned line, std::chrono::milliseconds width);
  Result<bool> WaitInPlace(bool logical, Clock::time_point deadline);
  void Update(const std::function<void(SlideState&)>& change);

  std::unique_ptr<GpioLines> lines_;
  SlideControllerConfig config_;
  std::mutex command_mutex_;  // one command at a time
  mutable std::mutex state_mutex_;
  SlideState state_;
  int unconfirmed_ = 0;  // the slide a timed-out change was going to (counting mode)
  std::function<void(const SlideState&)> listener_;
};

}  // namespace bsls::slides

#endif  // BSLS_SLIDES_SLIDE_CONTROLLER_H_
