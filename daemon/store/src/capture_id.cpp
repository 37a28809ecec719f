#include "bsls/store/capture_id.h"

#include <sys/random.h>

#include <random>

namespace bsls::store {

namespace {

constexpr char kHex[] = "0123456789abcdef";

void FillRandom(std::array<std::uint8_t, 10>& bytes) {
  std::size_t filled = 0;
  while (filled < bytes.size()) {
    const ssize_t got = ::getrandom(bytes.data() + filled, bytes.size() - filled, 0);
    if (got > 0) {
      filled += static_cast<std::size_t>(got);
    } else if (got < 0 && errno != EINTR) {
      // No getrandom (ancient kernel, seccomp): fall back to the C++ engine.
      std::random_device device;
      for (auto& byte : bytes) byte = static_cast<std::uint8_t>(device());
      return;
    }
  }
}

}  // namespace

std::optional<CaptureId> CaptureId::Parse(std::string_view text) {
  if (text.size() != 32) return std::nullopt;
  for (char c : text) {
    if (!((c >= '0' && c <= '9') || (c >= 'a' && c <= 'f'))) return std::nullopt;
  }
  return CaptureId(std::string(text));
}

CaptureIdGenerator::CaptureIdGenerator() { FillRandom(last_random_); }

CaptureId CaptureIdGenerator::Next(std::chrono::system_clock::time_point now) {
  const auto millis_signed =
      std::chrono::duration_cast<std::chrono::milliseconds>(now.time_since_epoch()).count();
  std::uint64_t millis = millis_signed < 0 ? 0 : static_cast<std::uint64_t>(millis_signed);
  millis &= (std::uint64_t{1} << 48) - 1;

  std::lock_guard lock(mutex_);
  if (millis > last_millis_) {
    last_millis_ = millis;
    FillRandom(last_random_);
    last_random_[0] &= 0x7F;  // leaves room to increment within the millisecond
  } else {
    // Same millisecond or the clock went back: keep the time, count up.
    for (int i = static_cast<int>(last_random_.size()) - 1; i >= 0; --i) {
      if (++last_random_[i] != 0) break;
      if (i == 0) ++last_millis_;  // 2^80 ids in one millisecond: move on
    }
  }
  std::string text(32, '0');
  for (int i = 0; i < 6; ++i) {
    const auto byte = static_cast<std::uint8_t>(last_millis_ >> (8 * (5 - i)));
    text[2 * i] = kHex[byte >> 4];
    text[2 * i + 1] = kHex[byte & 0xF];
  }
  for (std::size_t i = 0; i < last_random_.size(); ++i) {
    text[12 + 2 * i] = kHex[last_random_[i] >> 4];
    text[12 + 2 * i + 1] = kHex[last_random_[i] & 0xF];
  }
  return CaptureId(std::move(text));
}

}  // namespace bsls::store
