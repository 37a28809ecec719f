// The driver of the thesis's ISA frame-grabber card (thesis chapter 3 and
// Appendix C) over any PortIo: /dev/port, ioperm, or the card emulator.
//
// Protocol of one Grab (docs/hardware.md has the timing diagram):
//   1. card idle: S3 = 0 (a download still running is waited out)
//   2. SAMPLE 0->1: the PLD waits for the next odd field and digitises the
//      odd and even fields into SRAM1 and SRAM2 (states 0001..0110)
//   3. S3 = 1: digitised (state 1000)
//   4. SAMPLE 1->0: the PLD streams 131072 byte pairs; for each, wait for OE
//      low, read APIN (odd field) and BPIN (even field), wait for OE high
//   5. S3 = 0: the PLD is back in state 0000
//   6. interleave the fields into 512 x 512, extend black level 64..255 to 0..255
// Every wait polls port C with a timeout and ends in a Status naming the port,
// the line and the PLD step; nothing waits forever.
//
// The card streams pairs at its own pace without handshake (thesis 3.11: the
// DOS program disabled interrupts). A host that is preempted for longer than
// one OE pulse misses pairs; the driver notices (the card finishes before all
// pairs are read) and fails with kDataLoss rather than return a torn frame.
// The daemon should run grabs on a high-priority thread and may retry.
//
// Thread-safety: not thread-safe (see Framestore). With IopermPortIo, call
// from the thread that opened the port access.
#ifndef BSLS_FRAMESTORE_ISA_FRAMESTORE_H_
#define BSLS_FRAMESTORE_ISA_FRAMESTORE_H_

#include <array>
#include <chrono>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "bsls/framestore/framestore.h"
#include "bsls/framestore/isa_card.h"
#include "bsls/framestore/port_io.h"

namespace bsls::framestore {

struct IsaFramestoreParams {
  // 8255 base address as set by the card's DIP switches (thesis 3.9): a
  // multiple of 4 in 0x100..0x3FC. Default 0x300 (Table 3.1).
  std::uint32_t base = isa::kDefaultBase;
  // The cameras connected; camera c is on video input static_cast<int>(c).
  std::vector<Camera> cameras = {Camera::kLeft, Camera::kRight};
  Camera initial_camera = Camera::kLeft;   // must be one of `cameras`
  int initial_gain = isa::kUnityGainCode;  // DAC code 0..255

  // Read the control word back after writing it. The CMOS 82C55A returns it;
  // an NMOS 8255 does not (its control register is write-only): set false.
  bool verify_control_word = true;

  // Waits, all on the monotonic clock. Thesis timing in brackets.
  // A running download to finish before a grab may start [1.7 s].
  std::chrono::milliseconds idle_timeout{3000};
  // S3 must stay 0 this long (or for 5 video fields) before the card counts
  // as idle after an aborted grab or at open [a digitise takes <= 80 ms].
  std::chrono::milliseconds resync_quiet{100};
  // SAMPLE 0->1 until S3 = 1 [wait for odd field <= 40 ms + 2 fields 40 ms].
  std::chrono::milliseconds digitise_timeout{250};
  // One OE edge [one pair every 13 us, thesis 3.12].
  std::chrono::milliseconds pair_timeout{20};
  // All 131072 pairs [1.66 s, thesis Equation 3.4].
  std::chrono::milliseconds download_timeout{10000};

  // True when usable; otherwise names the field and the reason.
  bool IsValid(std::string* error) const;
};

// Thesis 3.11: the black level 64 extended to 0 and 255 kept at 255:
// out = round((code - 64) * 4/3), clamped to 0..255 (the thesis writes the
// factor as 1.333; both round every code 64..255 to the same value).
std::uint8_t ExtendBlackLevel(std::uint8_t code);

class IsaFramestore final : public Framestore {
 public:
  // Takes the port access, programs the 8255 (thesis 3.8: 0x93 at base+3),
  // checks that a card answers at `params.base`, sets camera and gain and
  // waits until the card is idle. kInvalidArgument for bad params (naming the
  // field), kUnavailable when no card answers, device errors otherwise.
  static Result<std::unique_ptr<IsaFramestore>> Open(std::unique_ptr<PortIo> io,
                                                     const IsaFramestoreParams& params);

  const Capabilities& capabilities() const override { return capabilities_; }
  Status SelectCamera(Camera camera) override;
  Status SetGain(int gain) override;
  Camera camera() const override { return camera_; }
  int gain() const override { return gain_; }
  Result<GreyFrame> Grab(const GrabOptions& options = {}) override;

  // The port access this driver uses (borrowed; lives as long as the driver).
  PortIo& port_io() { return *io_; }

 private:
  using Clock = std::chrono::steady_clock;
  enum class PollOutcome { kMet, kTimedOut, kCallerDeadline };

  IsaFramestore(std::unique_ptr<PortIo> io, const IsaFramestoreParams& params);
  Status Initialise();
  Status WriteRegister(int video_input, int gain_code);
  Status WaitIdle(Clock::time_point caller_deadline);
  Status Resync(Clock::time_point caller_deadline);
  Status Digitise(Clock::time_point caller_deadline);
  Status Download(Clock::time_point caller_deadline, std::vector<std::uint8_t>* odd,
                  std::vector<std::uint8_t>* even);
  PollOutcome PollPortC(std::uint8_t mask, std::uint8_t want, std::chrono::milliseconds timeout,
                        Clock::time_point caller_deadline, std::uint8_t* last);
  Status CheckIo(const char* step) const;
  void WriteCommand(std::uint8_t upper_nibble);
  std::uint8_t ReadPortC() { return io_->Inb(port_c_); }
  std::string Line(int bit, const char* name) const;

  std::unique_ptr<PortIo> io_;
  IsaFramestoreParams params_;
  Capabilities capabilities_;
  std::uint32_t port_c_;
  std::uint8_t command_ = 0;  // shadow of the port C output nibble
  Camera camera_;
  int gain_;
  bool resync_needed_ = true;
  std::uint64_t sequence_ = 0;
  std::array<std::uint8_t, 256> extend_lut_{};
};

}  // namespace bsls::framestore

#endif  // BSLS_FRAMESTORE_ISA_FRAMESTORE_H_
