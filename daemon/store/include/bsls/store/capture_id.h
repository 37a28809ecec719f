// Capture ids: opaque, unique, time-ordered 128-bit values written as 32
// lower-case hex digits (ULID layout: 48 bits of Unix milliseconds, then 80
// bits that are random for the first id of a millisecond and incremented for
// the next ones, so ids made by one generator sort in the order they were
// made). Clients treat them as opaque strings; the store uses them in file
// names, so only well-formed ids are ever accepted (Parse).
//
// Thread-safety: CaptureId is a value; CaptureIdGenerator is thread-safe.
#ifndef BSLS_STORE_CAPTURE_ID_H_
#define BSLS_STORE_CAPTURE_ID_H_

#include <array>
#include <chrono>
#include <cstdint>
#include <mutex>
#include <optional>
#include <string>
#include <string_view>

namespace bsls::store {

// A well-formed capture id (32 lower-case hex digits).
class CaptureId {
 public:
  // The id written as `text`; nullopt unless it is exactly 32 lower-case hex digits.
  static std::optional<CaptureId> Parse(std::string_view text);

  // The 32 hex digits.
  const std::string& str() const { return text_; }

  friend bool operator==(const CaptureId&, const CaptureId&) = default;
  friend auto operator<=>(const CaptureId&, const CaptureId&) = default;

 private:
  explicit CaptureId(std::string text) : text_(std::move(text)) {}
  friend class CaptureIdGenerator;

  std::string text_;
};

// Makes new ids; strictly increasing within one generator.
class CaptureIdGenerator {
 public:
  // Seeds the random part from the kernel (getrandom).
  CaptureIdGenerator();

  // A new id for the wall-clock time `now`; greater than every id this
  // generator returned before, even if the clock went backwards.
  CaptureId Next(std::chrono::system_clock::time_point now);

 private:
  std::mutex mutex_;
  std::uint64_t last_millis_ = 0;
  std::array<std::uint8_t, 10> last_random_{};
};

}  // namespace bsls::store

#endif  // BSLS_STORE_CAPTURE_ID_H_
