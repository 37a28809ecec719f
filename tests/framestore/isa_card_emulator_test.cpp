// The ISA card emulator at register level, without the driver: the 8255,
// the camera/gain register and the Appendix C state machine's timing.
#include "bsls/framestore/isa_card_emulator.h"

#include <gtest/gtest.h>

#include <chrono>
#include <vector>

#include "emulated_card.h"

namespace bsls::framestore {
namespace {

using namespace std::chrono_literals;
using isa::PldState;
using testing::Cameras;
using testing::MakePicture;

constexpr std::uint32_t kBase = isa::kDefaultBase;
constexpr std::uint32_t kPortC = kBase + isa::kPortC;
constexpr std::uint32_t kControl = kBase + isa::kControl;

Cameras FlatCameras(std::uint8_t grey = 100) {
  Cameras cameras;
  cameras.inputs[0] = MakePicture([grey](int, int) { return grey; });
  return cameras;
}

// Polls port C until (value & mask) == want; returns the emulated time then.
std::int64_t PollUntil(IsaCardEmulator& card, std::uint8_t mask, std::uint8_t want,
                       std::int64_t max_polls = 10'000'000) {
  for (std::int64_t i = 0; i < max_polls; ++i) {
    if ((card.Inb(kPortC) & mask) == want) return card.now().count();
  }
  ADD_FAILURE() << "port C never reached " << int(want) << " under mask " << int(mask);
  return -1;
}

// Waits until a power-on digitise/download the card started by itself is over.
void SettleAfterModeSet(IsaCardEmulator& card) {
  card.Outb(kControl, isa::kControlWord);
  // The power-on digitise ends in 1000 within 80 ms, then downloads (1.7 s).
  const std::int64_t limit = card.now().count() + 100'000'000;
  while (card.now().count() < limit) {
    card.Inb(kPortC);
    if (card.lines().state == PldState::kIdle && card.now().count() > 80'000'000) break;
  }
  PollUntil(card, isa::kS3, 0);
  ASSERT_EQ(card.lines().state, PldState::kIdle);
}

TEST(IsaCardEmulatorTest, PowerOnPortsAreInputsAndSampleIsPulledUp) {
  IsaCardEmulator card({}, FlatCameras().Source());
  // 8255 reset state: every port an input; PC7..PC4 undriven read 1.
  EXPECT_EQ(card.Inb(kPortC) & 0xF0, 0xF0);
  EXPECT_EQ(card.Inb(kControl), 0x00);  // no mode word yet
  EXPECT_TRUE(card.lines().sample);
  // The PLD saw SAMPLE = 1 and left state 0000 to wait for the field sync.
  EXPECT_EQ(card.lines().state, PldState::kWaitVsync);
}

TEST(IsaCardEmulatorTest, OnlyTheDecodedPortsAnswer) {
  IsaCardEmulator card({}, FlatCameras().Source());
  card.Outb(kControl, isa::kControlWord);
  EXPECT_EQ(card.Inb(kBase - 1), 0xFF);
  EXPECT_EQ(card.Inb(kBase + 4), 0xFF);
  EXPECT_EQ(card.Inb(0x310 + isa::kControl), 0xFF);
  EXPECT_EQ(card.Inb(kControl), isa::kControlWord);
}

TEST(IsaCardEmulatorTest, ModeWord0x93SplitsPortC) {
  IsaCardEmulator card({}, FlatCameras().Source());
  card.Outb(kControl, isa::kControlWord);
  EXPECT_EQ(card.lines().mode_word, 0x93);
  EXPECT_FALSE(card.lines().sample);  // a mode set clears the output latches
  card.Outb(kPortC, 0xA5);
  const std::uint8_t c = card.Inb(kPortC);
  EXPECT_EQ(c & 0xF0, 0xA0);          // output nibble reads back its latch
  EXPECT_EQ(c & isa::kOe, isa::kOe);  // input nibble: OE inactive (high)
  // Port A is an input: writing its output latch changes nothing on the pins.
  const std::uint8_t a = card.Inb(kBase + isa::kApin);
  card.Outb(kBase + isa::kApin, static_cast<std::uint8_t>(~a));
  EXPECT_EQ(card.Inb(kBase + isa::kApin), a);
}

TEST(IsaCardEmulatorTest, ModeWordWithOutputsReadsBackLatches) {
  IsaCardEmulator card({}, FlatCameras().Source());
  card.Outb(kControl, 0x80);  // mode 0, every port an output
  card.Outb(kBase + isa::kApin, 0x5A);
  card.Outb(kBase + isa::kBpin, 0xC3);
  card.Outb(kPortC, 0x3C);
  EXPECT_EQ(card.Inb(kBase + isa::kApin), 0x5A);
  EXPECT_EQ(card.Inb(kBase + isa::kBpin), 0xC3);
  EXPECT_EQ(card.Inb(kPortC), 0x3C);
}

TEST(IsaCardEmulatorTest, BitSetResetDrivesSample) {
  IsaCardEmulator card({}, FlatCameras().Source());
  card.Outb(kControl, isa::kControlWord);
  card.Outb(kControl, (isa::kSampleBit << 1) | 1);  // set PC4
  EXPECT_TRUE(card.lines().sample);
  EXPECT_EQ(card.Inb(kPortC) & isa::kSample, isa::kSample);
  card.Outb(kControl, isa::kSampleBit << 1);  // reset PC4
  EXPECT_FALSE(card.lines().sample);
}

TEST(IsaCardEmulatorTest, ShiftRegisterLatchesCameraAndGain) {
  IsaCardEmulator card({}, FlatCameras().Source());
  card.Outb(kControl, isa::kControlWord);
  const std::uint16_t word = isa::RegisterWord(2, 77);
  for (int bit = 15; bit >= 0; --bit) {
    const std::uint8_t sdi = ((word >> bit) & 1) ? isa::kSdi : 0;
    card.Outb(kPortC, sdi);
    card.Outb(kPortC, sdi | isa::kSclk);
  }
  EXPECT_EQ(card.lines().shift_register, word);
  EXPECT_EQ(card.lines().video_input, 0);  // not latched yet
  EXPECT_EQ(card.Inb(kPortC) & isa::kSdo, (word & 0x8000) ? isa::kSdo : 0);
  card.Outb(kPortC, 0);
  card.Outb(kPortC, isa::kLatch);
  EXPECT_EQ(card.lines().video_input, 2);
  EXPECT_EQ(card.lines().gain_code, 77);
}

TEST(IsaCardEmulatorTest, FieldFlagTogglesEveryTwentyMilliseconds) {
  IsaCardEmulator card({}, FlatCameras().Source());
  card.Outb(kControl, isa::kControlWord);
  const std::uint8_t first = card.Inb(kPortC) & isa::kField;
  const std::int64_t t1 = PollUntil(card, isa::kField, first ^ isa::kField);
  const std::int64_t t2 = PollUntil(card, isa::kField, first);
  const std::int64_t bus = 1000;  // ns per access: the time resolution of a poll
  EXPECT_NEAR(static_cast<double>(t2 - t1), 20e6, bus);
  EXPECT_EQ(t1 % 20'000'000 < bus, true) << "edge at a field start, t1 = " << t1;
}

// Appendix C.2 timing: SAMPLE 0->1 waits for the next odd field (0001),
// skips the top lines (0111), digitises 256 lines of the odd field then of
// the even field; S3 rises at the end of the even field's last line.
TEST(IsaCardEmulatorTest, DigitiseWaitsForNextOddFieldAndEndsAfterEvenField) {
  IsaCardEmulator card({}, FlatCameras().Source());
  SettleAfterModeSet(card);
  const std::int64_t sample_time = card.now().count();
  card.Outb(kPortC, isa::kSample);
  const std::int64_t s3_time = PollUntil(card, isa::kS3, isa::kS3);
  EXPECT_EQ(card.lines().state, PldState::kWaitDownload);

  const std::int64_t frame_ns = 40'000'000;
  const std::int64_t odd_start = (sample_time / frame_ns + 1) * frame_ns;
  const std::int64_t even_start = odd_start + 20'000'000;
  // Lines 29..284 of the field are sampled (28 skipped in 0111, then the next
  // CSYNCH); the last one ends 101 + 512 clocks after its sync, plus one clock
  // each in 0101 and 0110.
  const std::int64_t expected = even_start + 284 * 64'000 + (101 + 512 + 2) * 100;
  EXPECT_NEAR(static_cast<double>(s3_time), static_cast<double>(expected), 1000.0);
  EXPECT_EQ(card.counters().frames_digitised, 2);  // the power-on one and ours
}

// Appendix C.2 / thesis 3.12: one byte pair every 129 PLD clocks (130 at a
// line end), OE low for states 1010, 1011 and 32 counts of 1100.
TEST(IsaCardEmulatorTest, DownloadPulsesOeAtThesisPace) {
  Cameras cameras;
  cameras.inputs[0] = MakePicture([](int x, int y) { return static_cast<std::uint8_t>(x + y); });
  IsaCardEmulator card({}, cameras.Source());
  SettleAfterModeSet(card);
  card.Outb(kPortC, isa::kSample);
  PollUntil(card, isa::kS3, isa::kS3);
  card.Outb(kPortC, 0);
  std::vector<std::int64_t> falls, rises;
  std::vector<std::uint8_t> a_bytes, b_bytes;
  for (int pair = 0; pair < 4; ++pair) {
    falls.push_back(PollUntil(card, isa::kOe, 0));
    a_bytes.push_back(card.Inb(kBase + isa::kApin));
    b_bytes.push_back(card.Inb(kBase + isa::kBpin));
    rises.push_back(PollUntil(card, isa::kOe, isa::kOe));
  }
  for (int pair = 1; pair < 4; ++pair) {
    EXPECT_NEAR(static_cast<double>(falls[pair] - falls[pair - 1]), 12'900.0, 1000.0);
  }
  EXPECT_NEAR(static_cast<double>(rises[1] - falls[1]), 3'400.0, 1000.0);
  // Pair k carries SRAM1[k] on APIN and SRAM2[k] on BPIN: rows 0 and 1.
  for (int pair = 0; pair < 4; ++pair) {
    EXPECT_EQ(a_bytes[pair], AdcCode(static_cast<std::uint8_t>(pair + 0), 128));
    EXPECT_EQ(b_bytes[pair], AdcCode(static_cast<std::uint8_t>(pair + 1), 128));
  }
}

TEST(IsaCardEmulatorTest, UnreadPairsAreCountedAsMissedAndTheCardGoesIdle) {
  IsaCardEmulator card({}, FlatCameras().Source());
  SettleAfterModeSet(card);
  const EmulatorCounters before = card.counters();
  card.Outb(kPortC, isa::kSample);
  PollUntil(card, isa::kS3, isa::kS3);
  card.Outb(kPortC, 0);
  PollUntil(card, isa::kS3, 0);  // never reads APIN: misses every pair
  const EmulatorCounters after = card.counters();
  EXPECT_EQ(after.pairs_presented - before.pairs_presented, isa::kPairsPerFrame);
  EXPECT_EQ(after.pairs_missed - before.pairs_missed, isa::kPairsPerFrame);
  EXPECT_EQ(after.downloads_completed - before.downloads_completed, 1);
  EXPECT_EQ(card.lines().state, PldState::kIdle);
}

TEST(IsaCardEmulatorTest, FieldSramsHoldAlternateRowsThroughTheAdc) {
  Cameras cameras;
  cameras.inputs[0] =
      MakePicture([](int x, int y) { return static_cast<std::uint8_t>(y % 2 ? 200 : x % 50); });
  IsaCardEmulator card({}, cameras.Source());
  SettleAfterModeSet(card);
  card.Outb(kPortC, isa::kSample);
  PollUntil(card, isa::kS3, isa::kS3);
  const std::vector<std::uint8_t> odd = card.sram(0), even = card.sram(1);
  for (int line = 0; line < isa::kLinesPerField; line += 37) {
    for (int x = 0; x < isa::kSamplesPerLine; x += 13) {
      ASSERT_EQ(odd[line * 512 + x], AdcCode(static_cast<std::uint8_t>(x % 50), 128));
      ASSERT_EQ(even[line * 512 + x], AdcCode(200, 128));
    }
  }
}

TEST(IsaCardEmulatorTest, ManualClockDrivesTimeBeyondTheBus) {
  ManualEmulatorClock clock;
  IsaCardEmulatorParams params;
  params.clock = &clock;
  IsaCardEmulator card(params, FlatCameras().Source());
  card.Inb(kPortC);
  EXPECT_EQ(card.now(), 1us);  // one bus cycle
  clock.Advance(5ms);
  card.Inb(kPortC);
  EXPECT_EQ(card.now(), 5ms);  // the clock is ahead of the bus
  card.Inb(kPortC);            // the clock stands still: one bus cycle more
  EXPECT_EQ(card.now(), 5ms + 1us);
}

TEST(IsaCardEmulatorTest, AdcClampsBlackTo64AndScalesWithGain) {
  EXPECT_EQ(AdcCode(0, 128), 64);
  EXPECT_EQ(AdcCode(255, 128), 255);
  EXPECT_EQ(AdcCode(100, 128), 64 + 75);
  EXPECT_EQ(AdcCode(100, 64), 64 + 38);  // 37.5 rounds up
  EXPECT_EQ(AdcCode(200, 0), 64);
  EXPECT_EQ(AdcCode(255, 255), 255);  // saturates
}

TEST(IsaCardEmulatorTest, ParamsValidationNamesTheField) {
  std::string error;
  IsaCardEmulatorParams params;
  EXPECT_TRUE(params.IsValid(&error)) << error;
  params.base = 0x302;
  EXPECT_FALSE(params.IsValid(&error));
  EXPECT_NE(error.find("base"), std::string::npos);
  params = {};
  params.oe_extend_clocks = 200;
  EXPECT_FALSE(params.IsValid(&error));
  EXPECT_NE(error.find("pair_delay_clocks"), std::string::npos);
  params = {};
  params.top_skip_lines = 100;
  EXPECT_FALSE(params.IsValid(&error));
  EXPECT_NE(error.find("field_period"), std::string::npos);
}

}  // namespace
}  // namespace bsls::framestore
