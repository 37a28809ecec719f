// A register-level emulator of the thesis's ISA frame-grabber card, usable
// wherever a PortIo is: the ISA driver's real code runs against it in tests
// and in the daemon's emulated-hardware backend.
//
// What is modelled (docs/hardware.md, "The emulator"):
//   - the address decoder (thesis 3.9): the card answers at base..base+3 only;
//     other ports read 0xFF like an empty ISA bus;
//   - the 8255 (thesis 3.8): mode-set words decoded (group A/B modes and the
//     direction of A, B, C upper, C lower), bit set/reset of port C, output
//     latches cleared by a mode set, input ports reading the card's lines,
//     output ports reading back their latch, undriven inputs pulled up;
//     the control register reads back the last mode word (CMOS 82C55A);
//   - the camera/gain shift register on PC5..PC7 with read-back on PC2;
//   - video timing (Appendix C.1): 20 ms fields alternating odd/even, 64 us
//     lines, the field flag on PC3; all inputs share one (genlocked) timing;
//   - the PLD state machine 0000..1111 of Appendix C.2 at its 10 MHz clock,
//     with its two field SRAMs, the FRAME latch, the OE pulses and S3;
//   - the ADC (thesis 3.3): black clamped to code 64, AdcCode() below.
//
// Time: every port access takes at least one ISA bus cycle; emulated time is
// max(clock->Now(), previous access + bus_cycle). With no clock the card is
// purely bus-clocked: deterministic, and fast (a grab costs about 1.8 million
// accesses), yet the PLD sees the real ordering of fields, lines and pulses.
// With SteadyEmulatorClock it runs in real time.
//
// Thread-safety: every public member may be called from any thread; a mutex
// serialises them. The VideoSource is called with that mutex held.
#ifndef BSLS_FRAMESTORE_ISA_CARD_EMULATOR_H_
#define BSLS_FRAMESTORE_ISA_CARD_EMULATOR_H_

#include <array>
#include <chrono>
#include <cstdint>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "bsls/framestore/isa_card.h"
#include "bsls/framestore/port_io.h"

namespace bsls::framestore {

// A source of emulated time.
class EmulatorClock {
 public:
  virtual ~EmulatorClock() = default;
  // Time since an arbitrary fixed origin; never decreases.
  virtual std::chrono::nanoseconds Now() = 0;
};

// Real time: std::chrono::steady_clock since construction.
class SteadyEmulatorClock final : public EmulatorClock {
 public:
  std::chrono::nanoseconds Now() override;

 private:
  std::chrono::steady_clock::time_point origin_ = std::chrono::steady_clock::now();
};

// Time that moves only when told to (tests). Thread-safe.
class ManualEmulatorClock final : public EmulatorClock {
 public:
  std::chrono::nanoseconds Now() override;
  // Moves time forward by `step` (>= 0).
  void Advance(std::chrono::nanoseconds step);

 private:
  std::mutex mutex_;
  std::chrono::nanoseconds now_{0};
};

// One camera picture: 512 x 512 grey levels 0 (black) .. 255 (white), row
// major, top row first; row y is video line y (0-based) of the frame.
struct VideoFrame {
  int width = isa::kFrameWidth;
  int height = isa::kFrameHeight;
  std::vector<std::uint8_t> pixels;  // width * height
};

// The picture on video input `input` (0..2) during video frame `frame` (one
// every 40 ms of emulated time, from 0); nullptr when no camera is connected
// to that input (no sync: a digitise never completes). A picture that is not
// 512 x 512 counts as no camera.
using VideoSource = std::function<std::shared_ptr<const VideoFrame>(int input, std::int64_t frame)>;

// Thesis 3.3: what the ADC stores for grey level `grey` at gain `gain_code`:
// black clamped to 64, full white at unity gain (code 128) on 255, linear in
// between and clamped at 255: 64 + round(grey * 3/4 * gain_code / 128).
// ExtendBlackLevel (isa_framestore.h) inverts it to within 1 grey level.
std::uint8_t AdcCode(std::uint8_t grey, int gain_code);

// Ways the card can misbehave, for testing the driver's timeouts and checks.
struct EmulatorFaults {
  bool absent = false;  // no card decodes the base: every read 0xFF, writes lost
  std::optional<std::uint8_t> control_readback;  // base+3 reads this instead of the mode word
  // The PLD clock stops after this many byte pairs of a download
  // (0: before the first OE pulse). OE and S3 then stay as they were.
  std::optional<std::int64_t> stall_after_pairs;
  std::optional<bool> s3_stuck_at;  // the S3 line reads this in every state
  bool no_video = false;            // no sync on any input, as if every camera were unplugged
};

struct IsaCardEmulatorParams {
  std::uint32_t base = isa::kDefaultBase;  // DIP switches: multiple of 4 in 0x100..0x3FC
  // Borrowed, must outlive the emulator; nullptr: bus-clocked time only.
  EmulatorClock* clock = nullptr;
  std::chrono::nanoseconds bus_cycle{1000};  // least time per port access (ISA: ~1 us), >= 0

  // Video timing (Appendix C.1: PAL, 50 fields/s).
  std::chrono::nanoseconds field_period{20'000'000};
  std::chrono::nanoseconds line_period{64'000};
  // Lines skipped in state 0111 before the first sampled line of a field:
  // (312 lines per field - 256 sampled) / 2 centres the picture.
  int top_skip_lines = 28;

  // PLD timing in clocks of 100 ns (thesis 3.5: 20 MHz divided to 10 MHz).
  std::chrono::nanoseconds pld_clock{100};
  int line_delay_clocks = 101;  // state 0011 (Appendix C.2: 10.1 us)
  int pair_delay_clocks = 124;  // state 1100 (COUNT124); a pair takes this + 5 clocks
  int oe_extend_clocks = 32;    // OE held in 1100 while the delay count is below this

  // True when usable; otherwise names the field and the reason.
  bool IsValid(std::string* error) const;
};

// The lines and registers of the card as its hardware sees them, for tests.
struct EmulatorLines {
  std::uint8_t mode_word = 0;  // last mode-set word written (0 before any)
  bool sample = false;         // the SAMPLE line at the PLD
  int video_input = 0;         // SEL1..SEL0 from the latched register
  int gain_code = 0;           // gain DAC from the latched register
  std::uint16_t shift_register = 0;
  isa::PldState state = isa::PldState::kIdle;
  bool oe_active = false;  // OE asserted (the port line reads 0)
};

// Counts for tests and benchmarks.
struct EmulatorCounters {
  std::int64_t reads = 0;
  std::int64_t writes = 0;
  std::int64_t frames_digitised = 0;  // state 0110 with FRAME set
  std::int64_t downloads_completed = 0;
  std::int64_t pairs_presented = 0;  // OE pulses
  std::int64_t pairs_missed = 0;     // pulses during which APIN was never read
  std::int64_t source_calls = 0;     // VideoSource calls
};

class IsaCardEmulator final : public PortIo {
 public:
  // A card at params.base, powered on (all PLD flip-flops reset, 8255 in its
  // reset state: every port input). The source is called once per field
  // digitised; params must be valid (asserted: checking them is the caller's
  // job, see IsValid).
  IsaCardEmulator(const IsaCardEmulatorParams& params, VideoSource source);

  std::uint8_t Inb(std::uint32_t port) override;
  void Outb(std::uint32_t port, std::uint8_t value) override;
  PortRange range() const override { return kAllPorts; }  // it emulates the whole bus
  Status status() const override { return {}; }
  std::string Describe() const override { return "ISA card emulator"; }

  // Replaces the faults in force (none at construction).
  void SetFaults(const EmulatorFaults& faults);
  // The lines now (emulated time does not advance).
  EmulatorLines lines() const;
  // The counts so far.
  EmulatorCounters counters() const;
  // Emulated time of the last access.
  std::chrono::nanoseconds now() const;
  // The content of field SRAM 0 (odd) or 1 (even): 256 lines of 512 codes.
  std::vector<std::uint8_t> sram(int field) const;

 private:
  static constexpr std::int64_t kNever = INT64_MAX;

  void Tick();
  void AdvanceTo(std::int64_t t);
  void Enter(isa::PldState state, std::int64_t t);
  void Transition(std::int64_t t);
  void SampleLineChanged(std::int64_t t);
  void UpdateOutputPins(std::int64_t t);
  std::uint8_t ReadPortC();
  bool SampleLine() const { return (upper_pins_ & isa::kSample) != 0; }
  std::int64_t NextFieldStart(std::int64_t t, bool odd_only) const;
  std::int64_t NextLineSync(std::int64_t t) const;
  std::int64_t FieldIndex(std::int64_t t) const { return t / field_ns_; }
  const VideoFrame* Picture(std::int64_t field_index);
  void DigitiseLine();

  IsaCardEmulatorParams params_;
  VideoSource source_;
  std::int64_t field_ns_, line_ns_, clock_ns_, bus_ns_;

  mutable std::mutex mutex_;
  EmulatorFaults faults_;
  EmulatorCounters counters_;
  std::int64_t now_ = 0;  // emulated ns of the last access

  // 8255.
  std::uint8_t mode_word_ = 0;
  bool a_input_ = true, b_input_ = true, c_upper_input_ = true, c_lower_input_ = true;
  std::uint8_t latch_a_out_ = 0, latch_b_out_ = 0, latch_c_ = 0;

  // Camera/gain register.
  std::uint8_t upper_pins_ = 0xF0;  // PC7..PC4 as the card sees them (pulled up when undriven)
  std::uint16_t shift_ = 0, register_ = isa::RegisterWord(0, isa::kUnityGainCode);

  // PLD.
  isa::PldState state_ = isa::PldState::kIdle;
  std::int64_t next_event_ = kNever;  // time of the next transition
  std::int64_t oe_release_ = kNever;  // OE end inside state 1100
  bool oe_ = false;
  bool frame_ = false;  // FRAME latch: second field / even byte
  int line_ = 0, pixel_ = 0;
  int field_sram_ = 0;            // SRAM of the field being digitised (FIELD input)
  std::int64_t field_start_ = 0;  // start time of that field
  std::int64_t pairs_this_download_ = 0;
  bool pair_read_ = true;
  bool stalled_ = false;
  // The picture of (frame, input), fetched once per video frame.
  std::shared_ptr<const VideoFrame> picture_;
  std::int64_t picture_frame_ = -1;
  int picture_input_ = -1;
  std::array<std::vector<std::uint8_t>, 2> srams_;
  std::uint8_t apin_ = 0xFF, bpin_ = 0xFF;  // the card's output latches
};

}  // namespace bsls::framestore

#endif  // BSLS_FRAMESTORE_ISA_CARD_EMULATOR_H_
