#include "bsls/framestore/isa_card_emulator.h"

#include <algorithm>
#include <cassert>

namespace bsls::framestore {

using isa::PldState;

std::chrono::nanoseconds SteadyEmulatorClock::Now() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::steady_clock::now() -
                                                              origin_);
}

std::chrono::nanoseconds ManualEmulatorClock::Now() {
  std::lock_guard lock(mutex_);
  return now_;
}

void ManualEmulatorClock::Advance(std::chrono::nanoseconds step) {
  assert(step.count() >= 0);
  std::lock_guard lock(mutex_);
  now_ += step;
}

std::uint8_t AdcCode(std::uint8_t grey, int gain_code) {
  // Thesis 3.3: the TDA8708 clamps black to code 64; at unity gain the
  // white of a 0.3..1.0 V video signal lands on 255, so one grey level of the
  // camera is 3/4 of a code (the thesis's 3.11 factor 1.333 undoes it).
  // 64 + round(grey * 3/4 * gain_code / 128), rounding halves up.
  const int scaled = (grey * 3 * gain_code + 256) / 512;
  return static_cast<std::uint8_t>(std::min(255, isa::kBlackLevelCode + scaled));
}

bool IsaCardEmulatorParams::IsValid(std::string* error) const {
  auto fail = [&](const std::string& text) {
    if (error) *error = text;
    return false;
  };
  if (base < isa::kMinBase || base > isa::kMaxBase || base % isa::kBaseAlignment != 0) {
    return fail("base must be a multiple of 4 in 0x100..0x3FC (DIP switches A9..A2)");
  }
  if (bus_cycle.count() < 0) return fail("bus_cycle must be >= 0");
  if (pld_clock.count() <= 0) return fail("pld_clock must be > 0");
  if (line_period.count() <= 0) return fail("line_period must be > 0");
  if (field_period < line_period * (top_skip_lines + isa::kLinesPerField + 2)) {
    return fail("field_period must hold top_skip_lines + 256 sampled lines + 2 line periods");
  }
  if (top_skip_lines < 0) return fail("top_skip_lines must be >= 0");
  if (line_delay_clocks < 1) return fail("line_delay_clocks must be >= 1");
  if (pld_clock * (line_delay_clocks + isa::kSamplesPerLine + 2) > line_period) {
    return fail("line_delay_clocks + 512 samples must fit in one line_period");
  }
  if (oe_extend_clocks < 0) return fail("oe_extend_clocks must be >= 0");
  if (pair_delay_clocks <= oe_extend_clocks) {
    return fail("pair_delay_clocks must exceed oe_extend_clocks (OE must end inside state 1100)");
  }
  return true;
}

IsaCardEmulator::IsaCardEmulator(const IsaCardEmulatorParams& params, VideoSource source)
    : params_(params),
      source_(std::move(source)),
      field_ns_(params.field_period.count()),
      line_ns_(params.line_period.count()),
      clock_ns_(params.pld_clock.count()),
      bus_ns_(params.bus_cycle.count()) {
  [[maybe_unused]] std::string error;
  assert(params_.IsValid(&error));
  for (auto& sram : srams_) sram.assign(isa::kPairsPerFrame, 0);
  // Power-on: the 8255 resets with every port an input, so the PLD's pulled-up
  // SAMPLE input reads 1 and the state machine starts a digitise at once,
  // as the real card does (thesis LDF: OPTION PULLUP ALL).
  Enter(PldState::kIdle, 0);
}

// ---- time -----------------------------------------------------------------

void IsaCardEmulator::Tick() {
  std::int64_t t = now_ + bus_ns_;
  if (params_.clock != nullptr) t = std::max(t, params_.clock->Now().count());
  now_ = t;
  AdvanceTo(t);
}

void IsaCardEmulator::AdvanceTo(std::int64_t t) {
  while (!stalled_) {
    if (oe_release_ <= t && oe_release_ <= next_event_) {
      oe_ = false;  // Appendix C.2: OE extended through part of the 1100 delay
      oe_release_ = kNever;
      continue;
    }
    if (next_event_ > t) break;
    Transition(next_event_);
  }
}

std::int64_t IsaCardEmulator::NextFieldStart(std::int64_t t, bool odd_only) const {
  std::int64_t field = FieldIndex(t) + 1;
  if (odd_only && field % 2 != 0) ++field;  // even field indices are odd fields
  return field * field_ns_;
}

std::int64_t IsaCardEmulator::NextLineSync(std::int64_t t) const {
  const std::int64_t field_start = FieldIndex(t) * field_ns_;
  const std::int64_t sync = field_start + ((t - field_start) / line_ns_ + 1) * line_ns_;
  return std::min(sync, field_start + field_ns_);
}

const VideoFrame* IsaCardEmulator::Picture(std::int64_t field_index) {
  if (faults_.no_video) return nullptr;
  const std::int64_t frame = field_index / 2;
  const int input = (register_ & isa::kVideoInputMask) >> isa::kVideoInputShift;
  if (frame != picture_frame_ || input != picture_input_) {
    picture_frame_ = frame;
    picture_input_ = input;
    ++counters_.source_calls;
    picture_ = source_ ? source_(input, frame) : nullptr;
    if (picture_ && (picture_->width != isa::kFrameWidth || picture_->height != isa::kFrameHeight ||
                     picture_->pixels.size() !=
                         static_cast<std::size_t>(isa::kFrameWidth) * isa::kFrameHeight)) {
      picture_ = nullptr;  // not a picture this card can sync to
    }
  }
  return picture_.get();
}

// ---- the PLD state machine (thesis Appendix C.2) ----------------------------

void IsaCardEmulator::Enter(PldState state, std::int64_t t) {
  state_ = state;
  switch (state) {
    case PldState::kIdle:
      // 0000: wait for SAMPLE = 1 (sampled on the next clock edge).
      next_event_ = SampleLine() ? t + clock_ns_ : kNever;
      break;
    case PldState::kWaitVsync:
      // 0001: wait for VSYNCH. The first field must be an odd one, so that
      // both fields come from the same camera frame; the second is the next.
      next_event_ = NextFieldStart(t, /*odd_only=*/!frame_);
      break;
    case PldState::kTopDelay:
      // 0111: count line syncs past the blank lines at the top of the field.
      next_event_ = field_start_ + params_.top_skip_lines * line_ns_ + clock_ns_;
      break;
    case PldState::kWaitLine:
      next_event_ = NextLineSync(t);  // 0010: the next CSYNCH
      break;
    case PldState::kLineDelay:
      next_event_ = t + params_.line_delay_clocks * clock_ns_;  // 0011: 10.1 us
      break;
    case PldState::kDigitise:
      next_event_ = t + isa::kSamplesPerLine * clock_ns_;  // 0100: until EOL
      break;
    case PldState::kEndOfLine:
    case PldState::kEndOfField:
    case PldState::kEvenByte:
    case PldState::kCheckEol:
    case PldState::kCheckEof:
    case PldState::kNextPixel:
      next_event_ = t + clock_ns_;
      break;
    case PldState::kWaitDownload:
      // 1000: wait for SAMPLE = 0.
      next_event_ = SampleLine() ? kNever : t + clock_ns_;
      break;
    case PldState::kPairStart:
      // 1001: reset the delay counter. A stalled card stops its clock here.
      if (faults_.stall_after_pairs && pairs_this_download_ >= *faults_.stall_after_pairs) {
        stalled_ = true;
      }
      next_event_ = t + clock_ns_;
      break;
    case PldState::kOddByte:
      // 1010: OE and RAM_ACC: SRAM1's byte to APIN.
      if (!pair_read_) ++counters_.pairs_missed;
      pair_read_ = false;
      oe_ = true;
      apin_ = srams_[0][line_ * isa::kSamplesPerLine + pixel_];
      ++counters_.pairs_presented;
      ++pairs_this_download_;
      next_event_ = t + clock_ns_;
      break;
    case PldState::kPairDelay:
      // 1100: slow down for the PC bus; OE held while the count is low.
      oe_release_ = t + params_.oe_extend_clocks * clock_ns_;
      if (params_.oe_extend_clocks == 0) oe_ = false;
      next_event_ = t + params_.pair_delay_clocks * clock_ns_;
      break;
  }
}

void IsaCardEmulator::Transition(std::int64_t t) {
  switch (state_) {
    case PldState::kIdle:
      Enter(PldState::kWaitVsync, t);
      break;
    case PldState::kWaitVsync:
      if (Picture(FieldIndex(t)) == nullptr) {
        Enter(PldState::kWaitVsync, t);  // no sync on this input: keep waiting
        break;
      }
      // RES_LINE_C, RES_PIX_C; the FIELD input picks the SRAM (ADDR17).
      line_ = 0;
      pixel_ = 0;
      field_start_ = t;
      field_sram_ = FieldIndex(t) % 2 == 0 ? 0 : 1;
      Enter(PldState::kTopDelay, t);
      break;
    case PldState::kTopDelay:
      Enter(PldState::kWaitLine, t);
      break;
    case PldState::kWaitLine:
      Enter(PldState::kLineDelay, t);
      break;
    case PldState::kLineDelay:
      Enter(PldState::kDigitise, t);
      break;
    case PldState::kDigitise:
      DigitiseLine();
      Enter(PldState::kEndOfLine, t);
      break;
    case PldState::kEndOfLine:
      if (line_ == isa::kLinesPerField - 1) {
        Enter(PldState::kEndOfField, t);  // EOF
      } else {
        ++line_;
        Enter(PldState::kWaitLine, t);
      }
      break;
    case PldState::kEndOfField:
      if (!frame_) {
        frame_ = true;  // the second field
        Enter(PldState::kWaitVsync, t);
      } else {
        frame_ = false;  // FRAMERESET
        line_ = 0;
        pixel_ = 0;
        ++counters_.frames_digitised;
        Enter(PldState::kWaitDownload, t);
      }
      break;
    case PldState::kWaitDownload:
      pairs_this_download_ = 0;
      Enter(PldState::kPairStart, t);
      break;
    case PldState::kPairStart:
      Enter(PldState::kOddByte, t);
      break;
    case PldState::kOddByte:
      // 1011: FRAME = 1, SRAM2's byte to BPIN; OE stays on.
      frame_ = true;
      bpin_ = srams_[1][line_ * isa::kSamplesPerLine + pixel_];
      Enter(PldState::kEvenByte, t);
      break;
    case PldState::kEvenByte:
      Enter(PldState::kPairDelay, t);
      break;
    case PldState::kPairDelay:
      frame_ = false;
      oe_ = false;
      oe_release_ = kNever;
      Enter(PldState::kCheckEol, t);
      break;
    case PldState::kCheckEol:
      Enter(pixel_ == isa::kSamplesPerLine - 1 ? PldState::kCheckEof : PldState::kNextPixel, t);
      break;
    case PldState::kNextPixel:
      ++pixel_;
      Enter(PldState::kPairStart, t);
      break;
    case PldState::kCheckEof:
      pixel_ = 0;
      if (line_ == isa::kLinesPerField - 1) {
        line_ = 0;
        if (!pair_read_) ++counters_.pairs_missed;
        pair_read_ = true;
        ++counters_.downloads_completed;
        Enter(PldState::kIdle, t);
      } else {
        ++line_;
        Enter(PldState::kPairStart, t);
      }
      break;
  }
}

void IsaCardEmulator::DigitiseLine() {
  // 0100: one line of the field into its SRAM at (line, pixel), through the
  // ADC at the gain in force. The odd field holds frame rows 0, 2, 4, ...
  const VideoFrame* picture = picture_.get();
  const int gain = register_ & isa::kGainMask;
  const int row = 2 * line_ + field_sram_;
  std::uint8_t* out = &srams_[field_sram_][line_ * isa::kSamplesPerLine];
  for (int x = 0; x < isa::kSamplesPerLine; ++x) {
    const std::uint8_t grey =
        picture != nullptr ? picture->pixels[static_cast<std::size_t>(row) * isa::kFrameWidth + x]
                           : 0;
    out[x] = AdcCode(grey, gain);
  }
}

// ---- the 8255 and the card's lines -----------------------------------------

void IsaCardEmulator::UpdateOutputPins(std::int64_t t) {
  // Undriven lines (port C upper configured as input) are pulled up.
  const std::uint8_t pins = c_upper_input_ ? 0xF0 : (latch_c_ & 0xF0);
  const std::uint8_t rising = pins & ~upper_pins_;
  upper_pins_ = pins;
  if (rising & isa::kSclk) {
    shift_ = static_cast<std::uint16_t>((shift_ << 1) | ((pins & isa::kSdi) ? 1 : 0));
  }
  if (rising & isa::kLatch) register_ = shift_;
  // The PLD looks at SAMPLE in states 0000 and 1000 only.
  if (state_ == PldState::kIdle) {
    if (!SampleLine()) {
      next_event_ = kNever;
    } else if (next_event_ == kNever) {
      next_event_ = t + clock_ns_;
    }
  } else if (state_ == PldState::kWaitDownload) {
    if (SampleLine()) {
      next_event_ = kNever;
    } else if (next_event_ == kNever) {
      next_event_ = t + clock_ns_;
    }
  }
}

std::uint8_t IsaCardEmulator::ReadPortC() {
  std::uint8_t lower = 0;
  if (!oe_) lower |= isa::kOe;  // active low
  const bool s3 = faults_.s3_stuck_at.value_or((static_cast<int>(state_) & 0x8) != 0);
  if (s3) lower |= isa::kS3;
  if (shift_ & 0x8000) lower |= isa::kSdo;
  const std::int64_t field = FieldIndex(now_);
  if (field % 2 == 0 && Picture(field) != nullptr) lower |= isa::kField;
  const std::uint8_t upper = c_upper_input_ ? upper_pins_ : (latch_c_ & 0xF0);
  return static_cast<std::uint8_t>(upper | (c_lower_input_ ? lower : (latch_c_ & 0x0F)));
}

std::uint8_t IsaCardEmulator::Inb(std::uint32_t port) {
  std::lock_guard lock(mutex_);
  ++counters_.reads;
  Tick();
  if (faults_.absent || port < params_.base || port >= params_.base + isa::kPortCount) {
    return 0xFF;  // nothing decodes this address: the bus floats high
  }
  switch (port - params_.base) {
    case isa::kApin:
      if (!a_input_) return latch_a_out_;
      if (oe_) pair_read_ = true;
      return apin_;
    case isa::kBpin:
      return b_input_ ? bpin_ : latch_b_out_;
    case isa::kPortC:
      return ReadPortC();
    default:
      return faults_.control_readback.value_or(mode_word_);
  }
}

void IsaCardEmulator::Outb(std::uint32_t port, std::uint8_t value) {
  std::lock_guard lock(mutex_);
  ++counters_.writes;
  Tick();
  if (faults_.absent || port < params_.base || port >= params_.base + isa::kPortCount) return;
  switch (port - params_.base) {
    case isa::kApin:
      latch_a_out_ = value;
      break;
    case isa::kBpin:
      latch_b_out_ = value;
      break;
    case isa::kPortC:
      latch_c_ = value;  // only the bits of output groups reach the pins
      UpdateOutputPins(now_);
      break;
    default:
      if (value & 0x80) {
        // Mode set: D6 D5 group A mode, D4 A in, D3 C upper in, D2 group B
        // mode, D1 B in, D0 C lower in. Modes 1 and 2 are taken as mode 0
        // (their handshake lines are not wired on this card). A mode set
        // clears every output latch.
        mode_word_ = value;
        a_input_ = value & 0x10;
        c_upper_input_ = value & 0x08;
        b_input_ = value & 0x02;
        c_lower_input_ = value & 0x01;
        latch_a_out_ = latch_b_out_ = latch_c_ = 0;
      } else {
        // Bit set/reset of port C: D3..D1 bit number, D0 the value.
        const int bit = (value >> 1) & 0x7;
        latch_c_ = (value & 1) ? static_cast<std::uint8_t>(latch_c_ | (1u << bit))
                               : static_cast<std::uint8_t>(latch_c_ & ~(1u << bit));
      }
      UpdateOutputPins(now_);
      break;
  }
}

// ---- inspection --------------------------------------------------------------

void IsaCardEmulator::SetFaults(const EmulatorFaults& faults) {
  std::lock_guard lock(mutex_);
  faults_ = faults;
  if (stalled_ && !faults_.stall_after_pairs) {
    stalled_ = false;  // the clock runs again from now
    next_event_ = std::max(next_event_, now_);
    if (oe_release_ != kNever) oe_release_ = std::max(oe_release_, now_);
  }
  picture_frame_ = -1;  // re-ask the source (video may have come or gone)
}

EmulatorLines IsaCardEmulator::lines() const {
  std::lock_guard lock(mutex_);
  EmulatorLines lines;
  lines.mode_word = mode_word_;
  lines.sample = SampleLine();
  lines.video_input = (register_ & isa::kVideoInputMask) >> isa::kVideoInputShift;
  lines.gain_code = register_ & isa::kGainMask;
  lines.shift_register = shift_;
  lines.state = state_;
  lines.oe_active = oe_;
  return lines;
}

EmulatorCounters IsaCardEmulator::counters() const {
  std::lock_guard lock(mutex_);
  return counters_;
}

std::chrono::nanoseconds IsaCardEmulator::now() const {
  std::lock_guard lock(mutex_);
  return std::chrono::nanoseconds(now_);
}

std::vector<std::uint8_t> IsaCardEmulator::sram(int field) const {
  assert(field == 0 || field == 1);
  std::lock_guard lock(mutex_);
  return srams_[field];
}

}  // namespace bsls::framestore
