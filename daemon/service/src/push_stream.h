// Private to bsls::service: a server stream on gRPC's callback API that
// writes what its source has ready, one write outstanding at a time. A
// publisher (the capture thread, the event hub) wakes it when it has
// something; a completed write wakes it again. Between writes the stream
// holds no thread: a stream whose reader is slow takes the newest message
// when its write completes (the source decides what it skipped), and one
// whose reader stopped is ended by StalledWrites.
//
// Lifetime: gRPC owns the reactor until OnDone, which deletes it. Whoever
// may wake or end it later (a publisher's callback, the drain) holds a
// PushControl, which outlives the reactor and does nothing once it is done.
//
// Thread-safety: Wake and End from any thread; gRPC's reactions from its
// own. Decisions are made under the control's lock, gRPC is called
// without it (a reaction may run inline).
#ifndef BSLS_SERVICE_SRC_PUSH_STREAM_H_
#define BSLS_SERVICE_SRC_PUSH_STREAM_H_

#include <grpcpp/grpcpp.h>

#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <utility>

#include "bsls/service/stalled_writes.h"

namespace bsls::service::internal {

// What may wake or end a stream from outside.
class PushControl {
 public:
  virtual ~PushControl() = default;
  // The source may have a message: writes it unless a write is in flight.
  virtual void Wake() = 0;
  // Ends the stream with `status` once no write is in flight.
  virtual void End(grpc::Status status) = 0;
};

template <typename Message>
class PushStream final : public grpc::ServerWriteReactor<Message> {
 public:
  // The next message to write, or nullopt when there is none now. Called
  // under the stream's lock, never twice at once.
  using Source = std::function<std::optional<Message>()>;

  struct Options {
    grpc::CallbackServerContext* context = nullptr;
    StalledWrites* stalled = nullptr;    // watches each write
    const char* what = "";               // the stream's name in a stall's status
    bool send_initial_metadata = false;  // at once: the client learns the stream is open
    std::function<void()> on_done;       // after the call ended, before the reactor goes
  };

  // A new stream and its control; wake it (through the control) once its
  // source is connected. Use the reactor as the handler's return value.
  static std::pair<PushStream*, std::shared_ptr<PushControl>> Start(Options options) {
    auto* stream = new PushStream(std::move(options));
    return {stream, stream->control_};
  }

  // Connects the source (before the first Wake).
  void SetSource(Source source) { source_ = std::move(source); }

  void OnWriteDone(bool ok) override {
    {
      std::lock_guard lock(control_->mutex);
      control_->writing = false;
      watch_.reset();
      // A failed write: the call is cancelled or broken (a stalled reader
      // was ended with its own status already).
      if (!ok && !control_->ending) control_->ending = grpc::Status::CANCELLED;
    }
    control_->Wake();
  }

  void OnCancel() override { control_->End(grpc::Status::CANCELLED); }

  void OnDone() override {
    {
      std::lock_guard lock(control_->mutex);
      control_->stream = nullptr;
    }
    if (options_.on_done) options_.on_done();
    delete this;
  }

 private:
  struct Control final : PushControl {
    std::mutex mutex;
    PushStream* stream = nullptr;  // null once done
    bool writing = false;
    bool finished = false;               // Finish called
    std::optional<grpc::Status> ending;  // asked to end with this

    void Wake() override {
      PushStream* s = nullptr;
      enum { kNothing, kWrite, kFinish } action = kNothing;
      grpc::Status status;
      {
        std::lock_guard lock(mutex);
        if (stream == nullptr || finished || writing) return;
        s = stream;
        if (ending) {
          finished = true;
          status = *ending;
          action = kFinish;
        } else if (std::optional<Message> next = s->source_ ? s->source_() : std::nullopt) {
          s->current_ = std::move(*next);
          writing = true;
          if (s->options_.stalled)
            s->watch_.emplace(*s->options_.stalled, s->options_.context->c_call(),
                              s->options_.what);
          action = kWrite;
        }
      }
      // gRPC is called without the lock; the flags keep these two calls
      // from racing each other or OnDone (which follows Finish only).
      if (action == kWrite) s->StartWrite(&s->current_);
      if (action == kFinish) s->Finish(status);
    }

    void End(grpc::Status end_status) override {
      {
        std::lock_guard lock(mutex);
        if (stream == nullptr || finished) return;
        if (!ending) ending = std::move(end_status);
      }
      Wake();
    }
  };

  explicit PushStream(Options options)
      : options_(std::move(options)), control_(std::make_shared<Control>()) {
    control_->stream = this;
    if (options_.send_initial_metadata) this->StartSendInitialMetadata();
  }

  Options options_;
  std::shared_ptr<Control> control_;
  Source source_;
  Message current_;  // the message of the write in flight
  std::optional<StalledWrites::Watch> watch_;
};

// A publisher's callback that wakes the stream of `control` while it is
// open (it holds the control weakly: a publisher may outlive the stream).
inline std::function<void()> WakerOf(const std::shared_ptr<PushControl>& control) {
  return [weak = std::weak_ptr(control)] {
    if (auto c = weak.lock()) c->Wake();
  };
}

// A stream that ends at once with `status` (a refused call).
template <typename Message>
class EndedStream final : public grpc::ServerWriteReactor<Message> {
 public:
  explicit EndedStream(grpc::Status status) { this->Finish(std::move(status)); }
  void OnDone() override { delete this; }
};

}  // namespace bsls::service::internal

#endif  // BSLS_SERVICE_SRC_PUSH_STREAM_H_
