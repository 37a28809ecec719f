// A slide projector's mechanism at the GPIO line level, for machines without
// the real one (bslsd's simulated slide controller) and for the tests: the
// real SlideController drives it through the GpioLines interface exactly as
// it drives a chip.
//
// The model: a carousel of kSlides positions. A complete advance pulse
// (high for at least min_pulse, then low, at the lines' active level) starts
// a move -- to the slide coded on select1/select0 when those lines are
// configured, else one position on (3 wraps to 1). in_place drops as soon as
// a move starts and rises `travel` per position later. Lamp and focus lines
// are recorded. Faults: a jam (in_place never rises), in_place stuck.
#ifndef BSLS_SLIDES_EMULATED_SLIDE_CHANGER_H_
#define BSLS_SLIDES_EMULATED_SLIDE_CHANGER_H_

#include <condition_variable>
#include <map>
#include <mutex>
#include <optional>
#include <set>

#include "bsls/slides/gpio_lines.h"
#include "bsls/slides/slide_controller.h"

namespace bsls::slides {

struct EmulatedSlideChangerFaults {
  bool jammed = false;                   // moves start but never end
  std::optional<int> in_place_stuck_at;  // the input reads this level always
};

class EmulatedSlideChanger final : public GpioLines {
 public:
  // The mechanism wired as `config` says, carousel at config.initial_slide,
  // moving config.emulated_travel per position.
  explicit EmulatedSlideChanger(
      const SlideControllerConfig& config,
      std::chrono::milliseconds min_pulse = std::chrono::milliseconds(10));

  Status RequestOutput(unsigned offset, int initial) override;
  Status RequestInput(unsigned offset) override;
  Status Set(unsigned offset, int value) override;
  Result<int> Get(unsigned offset) override;
  Result<bool> WaitFor(unsigned offset, int value, Clock::time_point deadline) override;
  std::string Describe() const override { return "emulated slide mechanism"; }

  // For tests and status: where the carousel is, whether it moves.
  int position() const;
  bool moving() const;
  int focus_steps() const;  // + farther
  bool lamp_lit() const;
  int advances() const;  // complete advance pulses seen
  void SetFaults(const EmulatedSlideChangerFaults& faults);

 private:
  int Level(unsigned offset) const;  // physical level; mutex_ held
  int InPlaceLevel() const;          // mutex_ held
  bool Active(int level) const { return config_.active_low ? level == 0 : level == 1; }
  void Settle() const;  // finishes a move whose time has come; mutex_ held

  SlideControllerConfig config_;
  std::chrono::milliseconds min_pulse_;
  mutable std::mutex mutex_;
  std::condition_variable changed_;
  std::set<unsigned> outputs_, inputs_;
  std::map<unsigned, int> levels_;  // outputs' physical levels
  mutable int position_;
  mutable std::optional<int> target_;
  mutable Clock::time_point arrive_at_;
  Clock::time_point advance_rose_;
  int focus_steps_ = 0;
  int advances_ = 0;
  EmulatedSlideChangerFaults faults_;
};

}  // namespace bsls::slides

#endif  // BSLS_SLIDES_EMULATED_SLIDE_CHANGER_H_
