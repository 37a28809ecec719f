// Private to bsls::processing: the reply stream of a work call on gRPC's
// callback API. The worker that does the call's work pushes its events
// (progress, artifact chunks, the result) and at last its status; the
// stream writes them one at a time, and holds no thread in between. A
// progress event that has not gone out yet is replaced by the next one, so
// a slow reader sees the latest stage. Once the caller cancels, events are
// dropped and Push says so, and the stream finishes as soon as the work
// ends (gRPC keeps the request alive until then).
//
// Lifetime: gRPC owns the reactor until OnDone, which deletes it; End is the
// last call the work makes on it.
//
// Thread-safety: Push and End from the worker, the reactions from gRPC's
// threads; decisions under the lock, gRPC called without it.
#ifndef BSLS_PROCESSING_SRC_WORK_STREAM_H_
#define BSLS_PROCESSING_SRC_WORK_STREAM_H_

#include <grpcpp/grpcpp.h>

#include <deque>
#include <functional>
#include <mutex>
#include <optional>

#include "bsls/v1/processing.pb.h"

namespace bsls::processing::internal {

class WorkStream final : public grpc::ServerWriteReactor<v1::WorkEvent> {
 public:
  // `on_cancel` runs once when the caller cancels (it may End the stream);
  // set before the handler returns the stream.
  void SetOnCancel(std::function<void()> on_cancel) { on_cancel_ = std::move(on_cancel); }

  // Queues `event` for writing; false once the caller has gone.
  bool Push(v1::WorkEvent event) {
    std::unique_lock lock(mutex_);
    if (cancelled_ || status_) return false;
    if (event.has_progress() && outbox_.size() > (writing_ ? 1u : 0u) &&
        outbox_.back().has_progress())
      outbox_.back() = std::move(event);  // not written yet: the newer stage instead
    else
      outbox_.push_back(std::move(event));
    WriteNext(lock);
    return true;
  }

  // Ends the call with `status` once the queued events are written (at once
  // when the caller has gone).
  void End(grpc::Status status) {
    std::unique_lock lock(mutex_);
    if (status_) return;
    status_ = std::move(status);
    if (cancelled_) outbox_.erase(outbox_.begin() + (writing_ ? 1 : 0), outbox_.end());
    WriteNext(lock);
  }

  // True once the caller cancelled or a write failed.
  bool cancelled() const {
    std::lock_guard lock(mutex_);
    return cancelled_;
  }

  void OnWriteDone(bool ok) override {
    std::unique_lock lock(mutex_);
    writing_ = false;
    outbox_.pop_front();
    if (!ok) Cancelled(lock);
    if (lock.owns_lock()) WriteNext(lock);
  }

  void OnCancel() override {
    std::unique_lock lock(mutex_);
    Cancelled(lock);
  }

  void OnDone() override { delete this; }

 private:
  // The caller has gone: nothing more is written; `on_cancel_` runs once,
  // without the lock (it may End the stream). Leaves `lock` locked.
  void Cancelled(std::unique_lock<std::mutex>& lock) {
    if (cancelled_) return;
    cancelled_ = true;
    outbox_.erase(outbox_.begin() + (writing_ ? 1 : 0), outbox_.end());
    if (on_cancel_) {
      lock.unlock();
      on_cancel_();
      lock.lock();
    }
  }

  // Starts the next write, or the finish once the outbox is empty and the
  // status is known; called with `lock` held, returns with it released.
  void WriteNext(std::unique_lock<std::mutex>& lock) {
    if (writing_ || finished_) {
      lock.unlock();
      return;
    }
    if (!outbox_.empty() && !cancelled_) {
      writing_ = true;
      const v1::WorkEvent* next = &outbox_.front();  // stays put until OnWriteDone
      lock.unlock();
      StartWrite(next);
      return;
    }
    if (!status_) {
      lock.unlock();
      return;
    }
    finished_ = true;
    const grpc::Status status = *status_;
    lock.unlock();
    Finish(status);
  }

  std::function<void()> on_cancel_;
  mutable std::mutex mutex_;
  std::deque<v1::WorkEvent> outbox_;  // the front is being written while writing_
  bool writing_ = false;
  bool cancelled_ = false;
  bool finished_ = false;
  std::optional<grpc::Status> status_;
};

}  // namespace bsls::processing::internal

#endif  // BSLS_PROCESSING_SRC_WORK_STREAM_H_
