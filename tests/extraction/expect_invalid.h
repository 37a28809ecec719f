// Assertion helper of the extraction tests: invalid input must throw
// std::invalid_argument whose message names the function.
#ifndef BSLS_TESTS_EXTRACTION_EXPECT_INVALID_H_
#define BSLS_TESTS_EXTRACTION_EXPECT_INVALID_H_

#include <gtest/gtest.h>

#include <stdexcept>
#include <string>

namespace bsls::extraction::testing {

// Expects `call` to throw std::invalid_argument whose message contains `function`.
template <typename Call>
void ExpectInvalid(Call call, const std::string& function) {
  try {
    call();
    ADD_FAILURE() << "no exception from " << function;
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find(function), std::string::npos) << e.what();
  } catch (...) {
    ADD_FAILURE() << function << " threw something other than std::invalid_argument";
  }
}

}  // namespace bsls::extraction::testing

#endif  // BSLS_TESTS_EXTRACTION_EXPECT_INVALID_H_
