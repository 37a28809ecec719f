// The two sides of a session side by side: they are independent until the
// join, so each gets a core of the two the product runs on.
//
// Thread-safety: the callables run on two threads at once (the left on a
// thread of its own, the right on the caller's); they must not share
// mutable state.
#ifndef BSLS_SESSION_BOTH_SIDES_H_
#define BSLS_SESSION_BOTH_SIDES_H_

#include <exception>
#include <future>
#include <system_error>
#include <type_traits>
#include <utility>

namespace bsls::session {

// Runs `left` on a thread of its own and `right` on the calling thread and
// returns both results. When both throw, the left's exception is the one
// rethrown (as if they had run one after the other); without a thread to
// spare, the left runs on the calling thread after the right.
template <class Left, class Right>
auto RunBothSides(Left&& left, Right&& right)
    -> std::pair<std::invoke_result_t<Left>, std::invoke_result_t<Right>> {
  std::future<std::invoke_result_t<Left>> left_result;
  try {
    left_result = std::async(std::launch::async, left);
  } catch (const std::system_error&) {
    left_result = std::async(std::launch::deferred, left);
  }
  std::exception_ptr right_error;
  std::invoke_result_t<Right> right_value{};
  try {
    right_value = right();
  } catch (...) {
    right_error = std::current_exception();
  }
  auto left_value = left_result.get();
  if (right_error) std::rethrow_exception(right_error);
  return {std::move(left_value), std::move(right_value)};
}

}  // namespace bsls::session

#endif  // BSLS_SESSION_BOTH_SIDES_H_
