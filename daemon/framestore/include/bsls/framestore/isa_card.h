// The register map of the thesis's ISA frame-grabber card (thesis 3.8, 3.9,
// Table 3.1, Appendix C), shared by the driver (IsaFramestore) and the
// register-level emulator (IsaCardEmulator). docs/hardware.md has the same
// map with the reasons for the lines the thesis left spare.
//
//   base+0  APIN   in   odd-field byte  (SRAM1 via the card's output latch)
//   base+1  BPIN   in   even-field byte (SRAM2)
//   base+2  port C      upper nibble out (commands), lower nibble in (sync)
//   base+3  control     8255 control word, 0x93 = mode 0, A in, B in,
//                       C upper out, C lower in
//
// Port C bits (thesis 3.8 fixes PC0 = OE and PC4 = SAMPLE; the rest is ours):
//   PC0 in   OE      active LOW: a byte pair is on APIN/BPIN (thesis 3.8, 3.11)
//   PC1 in   S3      state bit S3 of the PLD: 1 = digitised / downloading
//   PC2 in   SDO     serial out of the camera/gain register (read-back)
//   PC3 in   FIELD   odd/even flag of the sync separator, 1 = odd field
//   PC4 out  SAMPLE  command to the PLD: 0->1 digitise, 1->0 download
//   PC5 out  SDI     serial data into the camera/gain register
//   PC6 out  SCLK    shifts SDI in on its rising edge
//   PC7 out  LATCH   copies the shift register to its outputs on its rising edge
//
// The camera/gain register: 16 bits, shifted in most significant bit first,
//   bits 15..10  reserved, 0
//   bits  9..8   video input (SEL1, SEL0): 0 left, 1 right, 2 third camera
//   bits  7..0   gain DAC code on the ADC's manual gain input; gain = code / 128
// Three spare output lines cannot carry 2 select bits and a gain word in
// parallel, hence the serial register (two 74HC595-style stages).
#ifndef BSLS_FRAMESTORE_ISA_CARD_H_
#define BSLS_FRAMESTORE_ISA_CARD_H_

#include <cstdint>

namespace bsls::framestore::isa {

// Thesis 3.9: A9..A2 are set by DIP switches, A1..A0 select the 8255 register.
inline constexpr std::uint32_t kDefaultBase = 0x300;  // Table 3.1
inline constexpr std::uint32_t kMinBase = 0x100;      // below: system-board devices
inline constexpr std::uint32_t kMaxBase = 0x3FC;      // 10-bit ISA decode, 4 registers
inline constexpr std::uint32_t kBaseAlignment = 4;
inline constexpr std::uint32_t kPortCount = 4;

inline constexpr std::uint32_t kApin = 0;     // offset of port A
inline constexpr std::uint32_t kBpin = 1;     // offset of port B
inline constexpr std::uint32_t kPortC = 2;    // offset of port C
inline constexpr std::uint32_t kControl = 3;  // offset of the control register

// Thesis 3.8: mode 0, port A in, port B in, C upper out, C lower in.
inline constexpr std::uint8_t kControlWord = 0x93;

// Port C lines.
inline constexpr std::uint8_t kOe = 0x01;      // PC0 in, active low
inline constexpr std::uint8_t kS3 = 0x02;      // PC1 in
inline constexpr std::uint8_t kSdo = 0x04;     // PC2 in
inline constexpr std::uint8_t kField = 0x08;   // PC3 in, 1 = odd field
inline constexpr std::uint8_t kSample = 0x10;  // PC4 out
inline constexpr std::uint8_t kSdi = 0x20;     // PC5 out
inline constexpr std::uint8_t kSclk = 0x40;    // PC6 out
inline constexpr std::uint8_t kLatch = 0x80;   // PC7 out
inline constexpr int kOeBit = 0, kS3Bit = 1, kSdoBit = 2, kFieldBit = 3;
inline constexpr int kSampleBit = 4, kSdiBit = 5, kSclkBit = 6, kLatchBit = 7;

// The camera/gain register.
inline constexpr int kRegisterBits = 16;
inline constexpr int kVideoInputShift = 8;
inline constexpr std::uint16_t kVideoInputMask = 0x0300;
inline constexpr std::uint16_t kGainMask = 0x00FF;
inline constexpr std::uint16_t kReservedMask = 0xFC00;
inline constexpr int kVideoInputs = 3;  // the TDA8708 has three inputs (thesis 3.3)
inline constexpr int kMinGainCode = 0;
inline constexpr int kMaxGainCode = 255;
inline constexpr int kUnityGainCode = 128;  // gain = code / kUnityGainCode

// The register word for a video input (0..2) and gain code (0..255).
constexpr std::uint16_t RegisterWord(int video_input, int gain_code) {
  return static_cast<std::uint16_t>((video_input << kVideoInputShift) | (gain_code & kGainMask));
}

// Picture geometry (thesis 3.4, Appendix C.1.3): two fields of 256 lines of
// 512 samples, each in its own 128 KiB SRAM; the odd field holds frame rows
// 0, 2, 4, ... (video lines 1, 3, 5, ... counted from 1), the even field
// rows 1, 3, 5, ...
inline constexpr int kSamplesPerLine = 512;
inline constexpr int kLinesPerField = 256;
inline constexpr int kFrameWidth = kSamplesPerLine;
inline constexpr int kFrameHeight = 2 * kLinesPerField;
inline constexpr int kPairsPerFrame = kSamplesPerLine * kLinesPerField;  // 131072

// Thesis 3.3: the TDA8708 clamps the black level to digital code 64.
inline constexpr int kBlackLevelCode = 64;

// The PLD states of thesis Appendix C.2 (S3 S2 S1 S0).
enum class PldState : std::uint8_t {
  kIdle = 0b0000,          // wait for SAMPLE 0->1
  kWaitVsync = 0b0001,     // wait for the field sync
  kWaitLine = 0b0010,      // wait for the next line sync (CSYNCH)
  kLineDelay = 0b0011,     // 101 clocks: sync pulse and back porch
  kDigitise = 0b0100,      // 512 samples into the field's SRAM
  kEndOfLine = 0b0101,     // EOL: last line of the field (EOF)?
  kEndOfField = 0b0110,    // FRAME latch: second field, or done
  kTopDelay = 0b0111,      // skip the blank lines at the top of the field
  kWaitDownload = 0b1000,  // digitised; wait for SAMPLE 1->0
  kPairStart = 0b1001,     // reset the delay counter
  kOddByte = 0b1010,       // OE on, SRAM1 byte to APIN
  kEvenByte = 0b1011,      // FRAME = 1, SRAM2 byte to BPIN
  kPairDelay = 0b1100,     // slow down for the PC bus; OE held for part of it
  kCheckEol = 0b1101,      // end of line?
  kCheckEof = 0b1110,      // end of frame? then back to kIdle
  kNextPixel = 0b1111,     // increment the pixel counter
};

}  // namespace bsls::framestore::isa

#endif  // BSLS_FRAMESTORE_ISA_CARD_H_
