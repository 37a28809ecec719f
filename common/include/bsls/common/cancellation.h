// Cancellation of long work: the caller's wish to stop (a cancelled call, a
// passed deadline, a service that drains), asked by the stages themselves
// at a fine grain (between stages, and every few rows, lines or iterations
// inside the long ones), so that a deadline frees a worker at once instead
// of when the work would have ended.
//
// A default Cancellation never asks to stop, so library calls without a
// caller to answer to (the CLI, tests, benchmarks) pass nothing.
//
// Errors: ThrowIfRequested throws Cancelled("cancelled during <where>").
//
// Thread-safety: the request function is called from whichever thread
// checks, the workers of cv::parallel_for_ included; it must be safe there
// (gRPC's ServerContext::IsCancelled, an atomic flag and a clock are).
#ifndef BSLS_COMMON_CANCELLATION_H_
#define BSLS_COMMON_CANCELLATION_H_

#include <atomic>
#include <functional>
#include <stdexcept>
#include <string>
#include <string_view>

namespace bsls {

// The work stopped because its caller asked; nothing is returned.
class Cancelled : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

class Cancellation {
 public:
  // Never asks to stop.
  Cancellation() = default;
  // Asks to stop whenever `requested` returns true.
  explicit Cancellation(std::function<bool()> requested) : requested_(std::move(requested)) {}

  // True when the caller asked to stop.
  bool Requested() const { return requested_ && requested_(); }
  // Throws Cancelled naming `where` when the caller asked to stop.
  void ThrowIfRequested(std::string_view where) const;

 private:
  std::function<bool()> requested_;
};

// A Cancellation asked by bands of work that run in parallel (one question
// per band): once one band hears stop, the bands after it skip their work
// without asking again, and the stage throws once they are done (an
// exception must not leave OpenCV's workers).
class BandStop {
 public:
  explicit BandStop(const Cancellation& cancel) : cancel_(cancel) {}

  // True when the caller asked to stop, in this band or an earlier one.
  bool Requested() {
    if (stopped_.load(std::memory_order_relaxed)) return true;
    if (!cancel_.Requested()) return false;
    stopped_.store(true, std::memory_order_relaxed);
    return true;
  }
  // Throws Cancelled naming `where` when a band heard stop (asks no more).
  void ThrowIfStopped(std::string_view where) const {
    if (stopped_.load(std::memory_order_relaxed))
      throw Cancelled("cancelled during " + std::string(where));
  }

 private:
  const Cancellation& cancel_;
  std::atomic<bool> stopped_{false};
};

}  // namespace bsls

#endif  // BSLS_COMMON_CANCELLATION_H_
