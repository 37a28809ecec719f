// libFuzzer entry of one parser target (parser_targets.h), compiled once per
// target with BSLS_PARSER_TARGET set to its name. A ContractViolation is a
// crash for libFuzzer: the input is saved and the message printed.
#include <cstdio>
#include <cstdlib>

#include "parser_targets.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const bsls::fuzz::ParserTarget* target = bsls::fuzz::FindParserTarget(BSLS_PARSER_TARGET);
  if (target == nullptr) {
    std::fprintf(stderr, "no parser target called %s\n", BSLS_PARSER_TARGET);
    std::abort();
  }
  try {
    (void)target->run(data, size);
  } catch (const bsls::fuzz::ContractViolation& e) {
    std::fprintf(stderr, "contract violation: %s\n", e.what());
    std::abort();
  }
  return 0;
}
