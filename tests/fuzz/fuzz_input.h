// The fuzzer's bytes read as a recipe: small numbers, choices and text taken
// one at a time from the front, so that a grammar (grammars.h) can turn any
// byte string into a structurally valid-ish document. Once the bytes run out
// every read gives its smallest choice (0, false, the first entry, ""), so a
// recipe always ends and always describes a finite document.
//
// Plain C++ (no libFuzzer header): the seed-replay test runs the same
// recipes under gcc. Thread-safety: one instance per thread.
#ifndef BSLS_TESTS_FUZZ_FUZZ_INPUT_H_
#define BSLS_TESTS_FUZZ_FUZZ_INPUT_H_

#include <cstddef>
#include <cstdint>
#include <initializer_list>
#include <string>
#include <string_view>
#include <vector>

namespace bsls::fuzz {

class FuzzInput {
 public:
  // Borrows `data` (size bytes) for the lifetime of this reader.
  FuzzInput(const std::uint8_t* data, std::size_t size) : data_(data), size_(size) {}

  // True while bytes are left to read.
  bool more() const { return pos_ < size_; }
  // Bytes not read yet.
  std::size_t remaining() const { return size_ - pos_; }

  // The next byte, 0 once the bytes ran out.
  std::uint8_t Byte() { return pos_ < size_ ? data_[pos_++] : 0; }
  // A number in [0, n) from one byte (n <= 256) or two (n > 256); 0 when n == 0.
  std::uint32_t Below(std::uint32_t n) {
    if (n <= 1) return 0;
    const std::uint32_t raw = n <= 256 ? Byte() : (std::uint32_t{Byte()} << 8 | Byte());
    return raw % n;
  }
  // True with probability about 1/2.
  bool Flip() { return (Byte() & 1) != 0; }
  // The next `n` bytes as a 64-bit big-endian number (n <= 8).
  std::uint64_t Bits(int n) {
    std::uint64_t value = 0;
    for (int i = 0; i < n; ++i) value = value << 8 | Byte();
    return value;
  }
  // One of `choices` (the first once the bytes ran out); `choices` not empty.
  template <typename T>
  const T& Pick(const std::vector<T>& choices) {
    return choices[Below(static_cast<std::uint32_t>(choices.size()))];
  }
  std::string_view Pick(std::initializer_list<std::string_view> choices) {
    return choices.begin()[Below(static_cast<std::uint32_t>(choices.size()))];
  }
  // Up to `max` raw bytes (their count from one byte).
  std::string Bytes(std::size_t max) {
    std::size_t n = Below(static_cast<std::uint32_t>(max + 1));
    std::string out;
    while (n-- > 0 && more()) out.push_back(static_cast<char>(Byte()));
    return out;
  }
  // What is left, as it is (the reader is then at its end).
  std::string Rest() {
    std::string out(reinterpret_cast<const char*>(data_ + pos_), size_ - pos_);
    pos_ = size_;
    return out;
  }

 private:
  const std::uint8_t* data_;
  std::size_t size_;
  std::size_t pos_ = 0;
};

}  // namespace bsls::fuzz

#endif  // BSLS_TESTS_FUZZ_FUZZ_INPUT_H_
