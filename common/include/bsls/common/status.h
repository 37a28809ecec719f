// The error type of the layers that report errors as values (the daemon's
// framestore, store, slides and service layers, bslsd): a code the gRPC
// layer maps one to one onto a grpc::StatusCode, and a message that names
// the input or the port/state and the reason. No exceptions cross the
// interfaces of those layers.
//
// Thread-safety: Status and Result are values.
#ifndef BSLS_COMMON_STATUS_H_
#define BSLS_COMMON_STATUS_H_

#include <cassert>
#include <optional>
#include <string>
#include <string_view>
#include <utility>

namespace bsls {

// What went wrong, in the vocabulary of gRPC status codes (same meanings).
enum class ErrorCode {
  kOk,
  kInvalidArgument,     // the caller's input is wrong (unknown camera, gain out of range, bad base)
  kFailedPrecondition,  // the device is in a state that forbids the call (card not idle)
  kPermissionDenied,    // the process lacks the privilege (CAP_SYS_RAWIO, lockdown)
  kUnavailable,         // the device is absent, lost, or not answering as the card would
  kDeadlineExceeded,    // a wait on the device ran out of time
  kDataLoss,            // data was lost on the way (missed OE pulses, short frame)
  kNotFound,            // the named thing does not exist (unknown capture id)
  kAlreadyExists,       // the thing to be created exists already
  kResourceExhausted,   // out of a resource: disk space below the reserve, quota
  kInternal,            // a bug of ours
};

// "ok", "invalid argument", "failed precondition", ... (lower case, for messages).
std::string_view ToString(ErrorCode code);

// Success, or an error code with a message for a human.
class Status {
 public:
  // Success.
  Status() = default;
  // An error; `code` must not be kOk.
  Status(ErrorCode code, std::string message) : code_(code), message_(std::move(message)) {
    assert(code != ErrorCode::kOk);
  }

  // True for success.
  bool ok() const { return code_ == ErrorCode::kOk; }
  // kOk or the error's code.
  ErrorCode code() const { return code_; }
  // Empty for success; otherwise names the input or port/state and the reason.
  const std::string& message() const { return message_; }
  // "ok", or "<code>: <message>".
  std::string ToString() const;

 private:
  ErrorCode code_ = ErrorCode::kOk;
  std::string message_;
};

// A value or the Status that says why there is none (C++20 has no std::expected).
template <typename T>
class Result {
 public:
  // A value.
  Result(T value) : value_(std::move(value)) {}  // NOLINT(google-explicit-constructor)
  // An error; `status` must not be ok.
  Result(Status status) : status_(std::move(status)) {  // NOLINT(google-explicit-constructor)
    assert(!status_.ok());
  }

  // True when a value is held.
  bool ok() const { return value_.has_value(); }
  // Ok when a value is held, else the error.
  const Status& status() const { return status_; }
  // The value; calling these without a value is a bug of the caller.
  T& value() & {
    assert(ok());
    return *value_;
  }
  const T& value() const& {
    assert(ok());
    return *value_;
  }
  T&& value() && {
    assert(ok());
    return std::move(*value_);
  }
  T* operator->() { return &value(); }
  const T* operator->() const { return &value(); }
  T& operator*() & { return value(); }
  const T& operator*() const& { return value(); }

 private:
  std::optional<T> value_;
  Status status_;
};

}  // namespace bsls

#endif  // BSLS_COMMON_STATUS_H_
