// The fuzz targets of the parsers of outside input (issue 26, "Fuzzing and
// tests"): the YAML loader every YAML reader goes through, the calibration
// manifest, the calibration file, bslsd's and bsls-processd's configuration
// files, PLY, OBJ, PNG frames and JSON. One function per parser, shared by
// the libFuzzer executables (parser_fuzz_main.cpp, clang) and the test that
// replays the seed corpus under any compiler (seed_replay_test.cpp).
//
// Each target feeds its input to the parser twice: as it is (so a seed is a
// real file and a mutated seed a damaged one), then as a recipe for the
// format's grammar (grammars.h), which makes structurally valid documents
// with the hostile shapes of the format. The parser must return a value that
// keeps its documented promises or throw its documented error; anything
// else -- another exception, a value outside the limits -- is a
// ContractViolation. Crashes, hangs and allocations above the limit are
// caught by libFuzzer (-timeout, -rss_limit_mb) and the sanitizers.
//
// Thread-safety: a target may be run from one thread at a time (the file
// targets share a scratch folder).
#ifndef BSLS_TESTS_FUZZ_PARSER_TARGETS_H_
#define BSLS_TESTS_FUZZ_PARSER_TARGETS_H_

#include <cstddef>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

namespace bsls::fuzz {

// A parser broke its contract on an input; what() names the parser and how.
class ContractViolation : public std::logic_error {
 public:
  using std::logic_error::logic_error;
};

struct ParserTarget {
  const char* name;    // also the folder of its seeds: seeds/<name>/
  const char* parser;  // what it calls, for messages
  // Runs one input (raw, then as a recipe); throws ContractViolation.
  // True when the parser accepted the input as it is (the raw run).
  bool (*run)(const std::uint8_t* data, std::size_t size);
};

// Every parser target, in a fixed order.
const std::vector<ParserTarget>& ParserTargets();

// The target called `name`, or nullptr.
const ParserTarget* FindParserTarget(std::string_view name);

// The folder of the checked-in seed corpus (one subfolder per target).
std::string SeedsDir();

}  // namespace bsls::fuzz

#endif  // BSLS_TESTS_FUZZ_PARSER_TARGETS_H_
