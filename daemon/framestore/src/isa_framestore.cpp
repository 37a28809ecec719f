#include "bsls/framestore/isa_framestore.h"

#include <algorithm>
#include <cstdio>
#include <set>

namespace bsls::framestore {
namespace {

using std::chrono::duration_cast;
using std::chrono::milliseconds;

std::string Hex(unsigned value, int digits = 0) {
  char text[16];
  std::snprintf(text, sizeof text, "0x%0*X", digits, value);
  return text;
}

std::string Ms(milliseconds ms) { return std::to_string(ms.count()) + " ms"; }

std::string CameraList(const std::vector<Camera>& cameras) {
  std::string text;
  for (Camera camera : cameras) text += (text.empty() ? "" : ", ") + ToString(camera);
  return text;
}

}  // namespace

// ---- params and pixel conversion ---------------------------------------------

bool IsaFramestoreParams::IsValid(std::string* error) const {
  auto fail = [&](const std::string& text) {
    if (error) *error = text;
    return false;
  };
  // Thesis 3.9: the DIP switches set A9..A2; A1..A0 select the 8255 register.
  if (base % isa::kBaseAlignment != 0) {
    return fail("base " + Hex(base) +
                " is not a multiple of 4: the card decodes A9..A2, A1..A0 select its registers");
  }
  if (base < isa::kMinBase) {
    return fail("base " + Hex(base) +
                " is in the system-board range 0x000-0x0FF; the card's switches give "
                "0x100..0x3FC (default 0x300)");
  }
  if (base > isa::kMaxBase) {
    return fail("base " + Hex(base) + " is above 0x3FC: the card decodes 10 address bits only");
  }
  if (cameras.empty()) return fail("cameras is empty: at least one camera must be connected");
  std::set<int> seen;
  for (Camera camera : cameras) {
    const int input = static_cast<int>(camera);
    if (input < 0 || input >= isa::kVideoInputs) {
      return fail("cameras: " + ToString(camera) + " is not one of the card's 3 video inputs");
    }
    if (!seen.insert(input).second) return fail("cameras lists " + ToString(camera) + " twice");
  }
  if (std::find(cameras.begin(), cameras.end(), initial_camera) == cameras.end()) {
    return fail("initial_camera " + ToString(initial_camera) + " is not one of cameras (" +
                CameraList(cameras) + ")");
  }
  if (initial_gain < isa::kMinGainCode || initial_gain > isa::kMaxGainCode) {
    return fail("initial_gain " + std::to_string(initial_gain) + " is outside 0..255");
  }
  const std::pair<const char*, milliseconds> timeouts[] = {{"idle_timeout", idle_timeout},
                                                           {"resync_quiet", resync_quiet},
                                                           {"digitise_timeout", digitise_timeout},
                                                           {"pair_timeout", pair_timeout},
                                                           {"download_timeout", download_timeout}};
  for (const auto& [name, value] : timeouts) {
    if (value.count() <= 0) return fail(std::string(name) + " must be > 0 ms");
  }
  return true;
}

std::uint8_t ExtendBlackLevel(std::uint8_t code) {
  // Thesis 3.11 (_extend()): subtract the old black level 64, multiply by
  // 1.333; round((code - 64) * 4 / 3) = floor((8 d + 3) / 6), clamped.
  const int d = code - isa::kBlackLevelCode;
  if (d <= 0) return 0;
  return static_cast<std::uint8_t>(std::min(255, (8 * d + 3) / 6));
}

// ---- opening -----------------------------------------------------------------

Result<std::unique_ptr<IsaFramestore>> IsaFramestore::Open(std::unique_ptr<PortIo> io,
                                                           const IsaFramestoreParams& params) {
  if (io == nullptr) return Status(ErrorCode::kInvalidArgument, "ISA framestore: no port access");
  std::string error;
  if (!params.IsValid(&error)) {
    return Status(ErrorCode::kInvalidArgument, "ISA framestore: " + error);
  }
  const PortRange card{params.base, isa::kPortCount};
  if (!io->range().Contains(card.first, card.count)) {
    return Status(ErrorCode::kInvalidArgument, "ISA framestore: port access " + io->Describe() +
                                                   " covers " + io->range().ToString() +
                                                   ", not the card's ports " + card.ToString());
  }
  std::unique_ptr<IsaFramestore> framestore(new IsaFramestore(std::move(io), params));
  if (Status status = framestore->Initialise(); !status.ok()) return status;
  return framestore;
}

IsaFramestore::IsaFramestore(std::unique_ptr<PortIo> io, const IsaFramestoreParams& params)
    : io_(std::move(io)),
      params_(params),
      port_c_(params.base + isa::kPortC),
      camera_(params.initial_camera),
      gain_(params.initial_gain) {
  capabilities_.backend = "isa";
  capabilities_.device =
      "thesis frame grabber, 8255 at " + Hex(params.base, 3) + " via " + io_->Describe();
  capabilities_.cameras = params.cameras;
  std::sort(capabilities_.cameras.begin(), capabilities_.cameras.end());
  capabilities_.gain = GainRange{isa::kMinGainCode, isa::kMaxGainCode, isa::kUnityGainCode,
                                 "gain DAC code, gain = code / 128"};
  capabilities_.width = isa::kFrameWidth;
  capabilities_.height = isa::kFrameHeight;
  for (int code = 0; code < 256; ++code) {
    extend_lut_[code] = ExtendBlackLevel(static_cast<std::uint8_t>(code));
  }
}

std::string IsaFramestore::Line(int bit, const char* name) const {
  return std::string(name) + " (port " + Hex(port_c_) + " bit " + std::to_string(bit) + ")";
}

Status IsaFramestore::CheckIo(const char* step) const {
  Status status = io_->status();
  if (status.ok()) return status;
  return Status(
      status.code() == ErrorCode::kInternal ? ErrorCode::kInternal : ErrorCode::kUnavailable,
      std::string(step) + ": " + status.message());
}

void IsaFramestore::WriteCommand(std::uint8_t upper_nibble) {
  command_ = upper_nibble & 0xF0;
  io_->Outb(port_c_, command_);
}

Status IsaFramestore::Initialise() {
  const std::uint32_t control = params_.base + isa::kControl;
  // Thesis 3.8: mode 0, A and B in, C upper out, C lower in. A mode set also
  // clears the output latches: SAMPLE = 0.
  io_->Outb(control, isa::kControlWord);
  command_ = 0;
  if (params_.verify_control_word) {
    const std::uint8_t readback = io_->Inb(control);
    if (readback != isa::kControlWord) {
      if (readback == 0xFF) {
        return Status(ErrorCode::kUnavailable,
                      "no card answers at base " + Hex(params_.base) +
                          ": the 8255 control register (port " + Hex(control) +
                          ") reads 0xFF after writing 0x93 (nothing decodes the address; check "
                          "the card's DIP switches A9..A2 against the configured base)");
      }
      return Status(ErrorCode::kUnavailable,
                    "the 8255 control register (port " + Hex(control) + ") reads back " +
                        Hex(readback, 2) +
                        " after writing 0x93: not the frame grabber's 8255, or an NMOS 8255 "
                        "whose control register cannot be read (set verify_control_word off)");
    }
  }
  // Port C upper nibble is an output latch and reads back (8255 mode 0).
  for (std::uint8_t pattern : {isa::kSdi, std::uint8_t{0}}) {
    WriteCommand(pattern);
    const std::uint8_t readback = ReadPortC() & 0xF0;
    if (readback != pattern) {
      return Status(ErrorCode::kUnavailable,
                    "port C (" + Hex(port_c_) + ") output nibble reads back " +
                        Hex(readback >> 4, 1) + " after writing " + Hex(pattern >> 4, 1) +
                        ": no 8255 in mode 0x93 at base " + Hex(params_.base));
    }
  }
  if (Status status = CheckIo("programming the 8255"); !status.ok()) return status;
  if (Status status = WriteRegister(static_cast<int>(camera_), gain_); !status.ok()) {
    return status;
  }
  return Resync(Clock::time_point::max());
}

// ---- camera and gain -----------------------------------------------------------

Status IsaFramestore::WriteRegister(int video_input, int gain_code) {
  // Our extension on the spare port C lines (isa_card.h, docs/hardware.md):
  // shift the word in twice, MSB first; during the second pass SDO returns the
  // first, which proves the register is there and the lines work; then latch.
  const std::uint16_t word = isa::RegisterWord(video_input, gain_code);
  const std::uint8_t keep = command_ & isa::kSample;
  std::uint16_t readback = 0;
  for (int pass = 0; pass < 2; ++pass) {
    for (int bit = isa::kRegisterBits - 1; bit >= 0; --bit) {
      const std::uint8_t data = ((word >> bit) & 1) ? isa::kSdi : 0;
      WriteCommand(keep | data);
      if (pass == 1) {
        readback =
            static_cast<std::uint16_t>((readback << 1) | ((ReadPortC() & isa::kSdo) ? 1 : 0));
      }
      WriteCommand(keep | data | isa::kSclk);
    }
  }
  WriteCommand(keep);
  if (readback != word) {
    return Status(ErrorCode::kUnavailable,
                  "camera/gain register: " + Line(isa::kSdoBit, "SDO") + " read back " +
                      Hex(readback, 4) + " after shifting in " + Hex(word, 4) +
                      " on SDI/SCLK (bits 5/6): the register is missing or a line is broken");
  }
  WriteCommand(keep | isa::kLatch);
  WriteCommand(keep);
  return CheckIo("writing the camera/gain register");
}

Status IsaFramestore::SelectCamera(Camera camera) {
  if (!capabilities_.HasCamera(camera)) {
    return Status(ErrorCode::kInvalidArgument, "camera " + ToString(camera) +
                                                   " is not connected to this ISA card (cameras: " +
                                                   CameraList(capabilities_.cameras) + ")");
  }
  if (Status status = WriteRegister(static_cast<int>(camera), gain_); !status.ok()) return status;
  camera_ = camera;
  return {};
}

Status IsaFramestore::SetGain(int gain) {
  if (!capabilities_.gain.Contains(gain)) {
    return Status(ErrorCode::kInvalidArgument, "gain " + std::to_string(gain) + " is outside " +
                                                   std::to_string(capabilities_.gain.min) + ".." +
                                                   std::to_string(capabilities_.gain.max) + " (" +
                                                   capabilities_.gain.unit + ")");
  }
  if (Status status = WriteRegister(static_cast<int>(camera_), gain); !status.ok()) return status;
  gain_ = gain;
  return {};
}

// ---- waits ----------------------------------------------------------------------

IsaFramestore::PollOutcome IsaFramestore::PollPortC(std::uint8_t mask, std::uint8_t want,
                                                    milliseconds timeout,
                                                    Clock::time_point caller_deadline,
                                                    std::uint8_t* last) {
  // The clock is read every 64 polls only (a poll is one bus cycle, ~1 us on
  // ISA); the timeout counts from the first reading.
  Clock::time_point deadline = Clock::time_point::max();
  for (unsigned i = 1;; ++i) {
    const std::uint8_t value = ReadPortC();
    *last = value;
    if ((value & mask) == want) return PollOutcome::kMet;
    if (i % 64 != 0) continue;
    const Clock::time_point now = Clock::now();
    if (i == 64) deadline = now + timeout;
    if (now >= caller_deadline) return PollOutcome::kCallerDeadline;
    if (now >= deadline) return PollOutcome::kTimedOut;
  }
}

Status IsaFramestore::WaitIdle(Clock::time_point caller_deadline) {
  // Thesis Appendix C.2: S3 = 0 in states 0000..0111; it is 1 while the card
  // holds a digitised frame or streams one out.
  std::uint8_t last = 0;
  const PollOutcome outcome = PollPortC(isa::kS3, 0, params_.idle_timeout, caller_deadline, &last);
  if (outcome == PollOutcome::kMet) return CheckIo("waiting for the card to be idle");
  if (outcome == PollOutcome::kCallerDeadline) {
    return Status(ErrorCode::kDeadlineExceeded,
                  "the caller's deadline passed while waiting for the card to be idle (" +
                      Line(isa::kS3Bit, "S3") + " = 1)");
  }
  return Status(ErrorCode::kFailedPrecondition,
                "card not idle: " + Line(isa::kS3Bit, "S3") + " stayed 1 for " +
                    Ms(params_.idle_timeout) +
                    " with SAMPLE = 0 (a download takes 1.7 s at the thesis pace): the PLD is "
                    "stuck in states 1000..1111 or S3 is stuck; port C reads " +
                    Hex(last, 2));
}

Status IsaFramestore::Resync(Clock::time_point caller_deadline) {
  // After power-on, an aborted grab or another program, the PLD may be
  // anywhere. With SAMPLE = 0 every path leads back to state 0000: a digitise
  // in progress ends in 1000 and streams itself out at once (S3 = 1 meanwhile).
  // The card counts as idle once S3 has stayed 0 for resync_quiet or for five
  // video fields (longer than any digitise).
  WriteCommand(command_ & ~isa::kSample);
  const Clock::time_point start = Clock::now();
  const Clock::time_point give_up =
      std::min(caller_deadline, start + params_.idle_timeout + params_.resync_quiet);
  Clock::time_point quiet_since = start;
  int field_edges = 0;
  std::uint8_t previous = ReadPortC();
  for (unsigned i = 1;; ++i) {
    const std::uint8_t value = ReadPortC();
    if (value & isa::kS3) {
      field_edges = -1;  // restart the count at the next S3 = 0
    } else {
      if (field_edges < 0) {
        field_edges = 0;
        quiet_since = Clock::now();
      }
      if ((value ^ previous) & isa::kField) ++field_edges;
      if (field_edges >= 5) break;
    }
    previous = value;
    if (i % 64 != 0) continue;
    const Clock::time_point now = Clock::now();
    if (field_edges >= 0 && now - quiet_since >= params_.resync_quiet) break;
    if (now >= give_up) {
      if (now >= caller_deadline) {
        return Status(ErrorCode::kDeadlineExceeded,
                      "the caller's deadline passed while waiting for the card to be idle");
      }
      return Status(ErrorCode::kFailedPrecondition,
                    "card not idle: " + Line(isa::kS3Bit, "S3") + " did not stay 0 for " +
                        Ms(params_.resync_quiet) + " within " +
                        Ms(params_.idle_timeout + params_.resync_quiet) +
                        " with SAMPLE = 0 (a download takes 1.7 s at the thesis pace): the PLD "
                        "is stuck in states 1000..1111 or S3 is stuck; port C reads " +
                        Hex(value, 2));
    }
  }
  if (Status status = CheckIo("waiting for the card to be idle"); !status.ok()) return status;
  resync_needed_ = false;
  return {};
}

// ---- grabbing ---------------------------------------------------------------------

Status IsaFramestore::Digitise(Clock::time_point caller_deadline) {
  // Thesis Appendix C.2: state 0000 waits for SAMPLE 0->1; 0001..0110 digitise
  // the next odd field and the even one into SRAM1 and SRAM2; 1000 (S3 = 1)
  // then waits for the download command.
  WriteCommand(command_ | isa::kSample);
  const std::uint8_t first = ReadPortC();
  std::uint8_t last = first;
  const PollOutcome outcome =
      PollPortC(isa::kS3, isa::kS3, params_.digitise_timeout, caller_deadline, &last);
  if (outcome == PollOutcome::kMet) return CheckIo("digitising");
  const std::string what = Line(isa::kS3Bit, "S3") + " stayed 0 after " +
                           Line(isa::kSampleBit, "SAMPLE") + " 0->1 (PLD states 0001..0110";
  if (outcome == PollOutcome::kCallerDeadline) {
    return Status(ErrorCode::kDeadlineExceeded,
                  "the caller's deadline passed while digitising: " + what + ")");
  }
  // Diagnose: is there video at all? The field flag toggles every 20 ms.
  std::uint8_t flag = last;
  const bool video = PollPortC(isa::kField, (last & isa::kField) ^ isa::kField, milliseconds(100),
                               caller_deadline, &flag) == PollOutcome::kMet;
  return Status(
      ErrorCode::kDeadlineExceeded,
      "digitise did not complete within " + Ms(params_.digitise_timeout) + ": " + what +
          "; a digitise takes at most 80 ms). " +
          (video ? std::string("Video sync is present: the PLD is not running or S3 is stuck at 0.")
                 : Line(isa::kFieldBit, "the field flag") +
                       " did not change for 100 ms: no video sync on camera " + ToString(camera_) +
                       " (input " + std::to_string(static_cast<int>(camera_)) + ")."));
}

Status IsaFramestore::Download(Clock::time_point caller_deadline, std::vector<std::uint8_t>* odd,
                               std::vector<std::uint8_t>* even) {
  // Thesis Appendix C.2: state 1000 waits for SAMPLE 1->0, then 1001..1111
  // put each pair of SRAM bytes on APIN/BPIN with an OE pulse, at the card's
  // own pace (thesis 3.12: 130 clocks of 100 ns per pair).
  WriteCommand(command_ & ~isa::kSample);
  const Clock::time_point download_deadline =
      std::min(caller_deadline, Clock::now() + params_.download_timeout);
  const std::uint32_t apin = params_.base + isa::kApin;
  const std::uint32_t bpin = params_.base + isa::kBpin;
  std::uint8_t last = 0;
  auto failure = [&](int pair, PollOutcome outcome, bool waiting_for_low) {
    const std::string where = "pair " + std::to_string(pair) + " of " +
                              std::to_string(isa::kPairsPerFrame) + " (field line " +
                              std::to_string(pair / isa::kSamplesPerLine) + ", sample " +
                              std::to_string(pair % isa::kSamplesPerLine) + ")";
    if (outcome == PollOutcome::kCallerDeadline) {
      const bool own = Clock::now() >= download_deadline && caller_deadline > download_deadline;
      if (!own) {
        return Status(ErrorCode::kDeadlineExceeded,
                      "the caller's deadline passed while downloading, at " + where);
      }
      return Status(ErrorCode::kDeadlineExceeded,
                    "download took longer than " + Ms(params_.download_timeout) + ", at " + where);
    }
    if (waiting_for_low && !(last & isa::kS3)) {
      return Status(ErrorCode::kDataLoss,
                    "download lost byte pairs: the card finished (" + Line(isa::kS3Bit, "S3") +
                        " fell to 0) while waiting for " + where +
                        ": the host missed OE pulses (preempted for longer than one 13 us "
                        "pulse?); retry the grab");
    }
    return Status(ErrorCode::kDeadlineExceeded,
                  "the card stopped answering during the download: " + Line(isa::kOeBit, "OE") +
                      " stayed " + (waiting_for_low ? "high" : "low") + " for " +
                      Ms(params_.pair_timeout) + " at " + where + " with S3 = " +
                      ((last & isa::kS3) ? "1" : "0") + "; port C reads " + Hex(last, 2));
  };
  for (int pair = 0; pair < isa::kPairsPerFrame; ++pair) {
    // Thesis 3.11: wait as long as OE is high (not active).
    PollOutcome outcome = PollPortC(isa::kOe, 0, params_.pair_timeout, download_deadline, &last);
    if (outcome != PollOutcome::kMet) return failure(pair, outcome, true);
    // Thesis 3.11: OE = 0: the odd byte is at APIN, the even byte at BPIN.
    (*odd)[pair] = io_->Inb(apin);
    (*even)[pair] = io_->Inb(bpin);
    // The pulse must end before the next one can be told apart.
    outcome = PollPortC(isa::kOe, isa::kOe, params_.pair_timeout, download_deadline, &last);
    if (outcome != PollOutcome::kMet) return failure(pair, outcome, false);
  }
  // Appendix C.2: after the last pair, state 1110 returns to 0000 (S3 = 0).
  const PollOutcome outcome =
      PollPortC(isa::kS3, 0, params_.pair_timeout, download_deadline, &last);
  if (outcome != PollOutcome::kMet) {
    return Status(outcome == PollOutcome::kCallerDeadline ? ErrorCode::kDeadlineExceeded
                                                          : ErrorCode::kUnavailable,
                  Line(isa::kS3Bit, "S3") + " still reads 1 " + Ms(params_.pair_timeout) +
                      " after the last of " + std::to_string(isa::kPairsPerFrame) +
                      " pairs: the PLD did not return to state 0000 (S3 stuck?)");
  }
  return CheckIo("downloading");
}

Result<GreyFrame> IsaFramestore::Grab(const GrabOptions& options) {
  const Clock::time_point caller_deadline = options.deadline.value_or(Clock::time_point::max());
  if (Clock::now() >= caller_deadline) {
    return Status(ErrorCode::kDeadlineExceeded, "the caller's deadline passed before the grab");
  }
  GreyFrame frame;
  frame.camera = camera_;
  frame.gain = gain_;
  std::vector<std::uint8_t> odd(isa::kPairsPerFrame), even(isa::kPairsPerFrame);

  Status status = resync_needed_ ? Resync(caller_deadline) : WaitIdle(caller_deadline);
  if (status.ok()) {
    frame.timestamps.requested = Clock::now();
    status = Digitise(caller_deadline);
  }
  if (status.ok()) {
    frame.timestamps.exposed = Clock::now();
    status = Download(caller_deadline, &odd, &even);
  }
  if (!status.ok()) {
    // Leave SAMPLE low and let the next grab find out where the card is.
    WriteCommand(command_ & ~isa::kSample);
    resync_needed_ = true;
    return status;
  }
  frame.timestamps.delivered = Clock::now();
  frame.timestamps.wall = std::chrono::system_clock::now();

  // Thesis 3.11 and Appendix C.1.3: the odd field (SRAM1, APIN) holds frame
  // rows 0, 2, 4, ..., the even field (SRAM2, BPIN) rows 1, 3, 5, ...; each
  // code goes through _extend() (black level 64 -> 0).
  frame.width = isa::kFrameWidth;
  frame.height = isa::kFrameHeight;
  frame.stride = isa::kFrameWidth;
  frame.pixels.resize(static_cast<std::size_t>(frame.stride) * frame.height);
  for (int line = 0; line < isa::kLinesPerField; ++line) {
    const std::uint8_t* odd_line = &odd[line * isa::kSamplesPerLine];
    const std::uint8_t* even_line = &even[line * isa::kSamplesPerLine];
    std::uint8_t* row0 = &frame.pixels[static_cast<std::size_t>(2 * line) * frame.stride];
    std::uint8_t* row1 = row0 + frame.stride;
    for (int x = 0; x < isa::kSamplesPerLine; ++x) {
      row0[x] = extend_lut_[odd_line[x]];
      row1[x] = extend_lut_[even_line[x]];
    }
  }
  frame.sequence = ++sequence_;
  return frame;
}

}  // namespace bsls::framestore
