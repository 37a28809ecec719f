// Raw gRPC calls for the malformed-request test: any bytes as the request
// messages of any method (grpc::GenericStub, so nothing is checked or parsed
// on the client), any number of them, with or without the half-close, and
// cancelled at a chosen time or after a chosen number of replies. Also the
// protobuf mutations the test builds its requests with: absurd values for a
// field found by reflection, truncations and bit flips.
#ifndef BSLS_TESTS_PROCESSING_RAW_CALLS_H_
#define BSLS_TESTS_PROCESSING_RAW_CALLS_H_

#include <google/protobuf/descriptor.h>
#include <google/protobuf/message.h>
#include <grpcpp/generic/generic_stub.h>
#include <grpcpp/grpcpp.h>
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <cstdint>
#include <limits>
#include <random>
#include <string>
#include <vector>

namespace bsls::processing::test {

namespace pb = google::protobuf;
using Rng = std::mt19937_64;

// One raw call: the method's full name and the request messages as bytes.
struct RawCall {
  std::string method;                 // "/bsls.v1.Processing/ProcessFrame"
  std::vector<std::string> messages;  // each sent as one message, as is
  bool half_close = true;             // WritesDone after the messages
  int cancel_after_replies = -1;      // TryCancel once this many replies came (-1: never)
  int cancel_after_ms = -1;           // TryCancel this long after the start (-1: never)
  int deadline_ms = 20000;
  std::string category;  // what kind of damage, for the tally
};

// How it ended.
struct RawOutcome {
  grpc::StatusCode code = grpc::StatusCode::UNKNOWN;
  std::string message;
  int replies = 0;
  bool hung = false;  // the call did not end by its deadline + 15 s (client side)
  double seconds = 0;
};

// Sends `call` on `stub` and waits for its end (status, replies read).
inline RawOutcome SendRaw(grpc::GenericStub& stub, const RawCall& call) {
  using SystemClock = std::chrono::system_clock;
  const auto start = SystemClock::now();
  const auto deadline = start + std::chrono::milliseconds(call.deadline_ms);
  const auto give_up = deadline + std::chrono::seconds(15);
  const auto cancel_at = call.cancel_after_ms >= 0
                             ? start + std::chrono::milliseconds(call.cancel_after_ms)
                             : SystemClock::time_point::max();
  grpc::ClientContext context;
  context.set_deadline(deadline);
  grpc::CompletionQueue queue;
  RawOutcome out;
  bool cancelled = false;
  // Waits for the operation tagged `tag`; cancels the call when its time
  // comes; false when the operation failed (the stream is over).
  auto wait = [&](std::intptr_t tag) {
    for (;;) {
      void* got = nullptr;
      bool ok = false;
      const auto until = cancelled ? give_up : std::min(cancel_at, give_up);
      const auto status = queue.AsyncNext(&got, &ok, until);
      if (status == grpc::CompletionQueue::GOT_EVENT) {
        if (reinterpret_cast<std::intptr_t>(got) == tag) return ok;
        continue;
      }
      if (status == grpc::CompletionQueue::SHUTDOWN) return false;
      if (!cancelled && SystemClock::now() >= cancel_at) {
        context.TryCancel();
        cancelled = true;
      } else if (SystemClock::now() >= give_up) {
        out.hung = true;
        context.TryCancel();
        cancelled = true;
      }
    }
  };
  std::unique_ptr<grpc::GenericClientAsyncReaderWriter> stream =
      stub.PrepareCall(&context, call.method, &queue);
  stream->StartCall(reinterpret_cast<void*>(1));
  bool ok = wait(1);
  for (const std::string& bytes : call.messages) {
    if (!ok) break;
    grpc::Slice slice(bytes);
    grpc::ByteBuffer buffer(&slice, 1);
    stream->Write(buffer, reinterpret_cast<void*>(2));
    ok = wait(2);
  }
  if (ok && call.half_close) {
    stream->WritesDone(reinterpret_cast<void*>(3));
    wait(3);
  }
  for (;;) {
    grpc::ByteBuffer reply;
    stream->Read(&reply, reinterpret_cast<void*>(4));
    if (!wait(4)) break;
    ++out.replies;
    if (call.cancel_after_replies >= 0 && out.replies >= call.cancel_after_replies && !cancelled) {
      context.TryCancel();
      cancelled = true;
    }
  }
  grpc::Status status;
  stream->Finish(&status, reinterpret_cast<void*>(5));
  wait(5);
  queue.Shutdown();
  void* got = nullptr;
  bool drained = false;
  while (queue.Next(&got, &drained)) {
  }
  out.code = status.error_code();
  out.message = status.error_message();
  out.seconds = std::chrono::duration<double>(SystemClock::now() - start).count();
  return out;
}

// Bytes that no request message parses from.
inline constexpr char kNotAMessage[] = "\x0a\xff\xff\xff\xff\x0f";

// Sends kNotAMessage to every method of `service` that takes one request
// and expects each refused with INVALID_ARGUMENT naming the request type
// (in a request stream a malformed message reads as the stream's end, so
// those are left out); returns how many methods were tried.
inline int ExpectMalformedRequestsRefused(grpc::GenericStub& stub,
                                          const pb::ServiceDescriptor& service) {
  int tried = 0;
  for (int i = 0; i < service.method_count(); ++i) {
    const pb::MethodDescriptor* method = service.method(i);
    if (method->client_streaming()) continue;
    RawCall call;
    call.method = "/" + service.full_name() + "/" + method->name();
    call.messages = {std::string(kNotAMessage, sizeof kNotAMessage - 1)};
    call.deadline_ms = 10000;
    const RawOutcome outcome = SendRaw(stub, call);
    EXPECT_EQ(outcome.code, grpc::StatusCode::INVALID_ARGUMENT) << call.method;
    EXPECT_NE(outcome.message.find(method->input_type()->full_name()), std::string::npos)
        << call.method << ": " << outcome.message;
    ++tried;
  }
  return tried;
}

// A uniform pick in [0, n).
inline int Pick(Rng& rng, int n) { return std::uniform_int_distribution<int>(0, n - 1)(rng); }

// One of `values`, uniformly.
template <typename T>
const T& OneOf(Rng& rng, const std::vector<T>& values) {
  return values[static_cast<std::size_t>(Pick(rng, static_cast<int>(values.size())))];
}

// `n` random bytes.
inline std::string RandomBytes(Rng& rng, std::size_t n) {
  std::string bytes(n, '\0');
  for (char& c : bytes) c = static_cast<char>(rng());
  return bytes;
}

// Random bytes of a length spread over 0 .. 64 KiB (mostly short).
inline std::string RandomMessage(Rng& rng) {
  switch (Pick(rng, 8)) {
    case 0:
      return "";
    case 1:
    case 2:
      return RandomBytes(rng, 1 + Pick(rng, 8));
    case 3:
    case 4:
    case 5:
      return RandomBytes(rng, 9 + Pick(rng, 256));
    case 6:
      return RandomBytes(rng, 257 + Pick(rng, 4096));
    default:
      return RandomBytes(rng, 4097 + Pick(rng, 60 << 10));
  }
}

// A text no sane field holds: empty, NUL, over the 256-byte limits, 60 KiB,
// paths out of a folder, a calibration id of nothing, format directives,
// non-UTF-8 bytes (a proto3 string field holding them fails to parse).
inline std::string AbsurdText(Rng& rng) {
  switch (Pick(rng, 11)) {
    case 0:
      return "";
    case 1:
      return std::string(1, '\0');
    case 2:
      return std::string(257, 'x');
    case 3:
      return std::string(60 << 10, 'y');
    case 4:
      return "../../../../../etc/passwd";
    case 5:
      return "/etc/passwd";
    case 6:
      return "sha256:" + std::string(64, 'f');
    case 7:
      return "%s%n%x%p{}{0}";
    case 8:
      return "\xc3\xa9t\xc3\xa9 \xe2\x82\xac";  // valid UTF-8
    case 9:
      return "\xff\xfe\xfd";
    default:
      return RandomBytes(rng, 1 + Pick(rng, 512));
  }
}

// Sets (add = false) or appends (add = true, repeated fields) an absurd value
// of `field`'s type.
inline void SetAbsurd(pb::Message* message, const pb::FieldDescriptor* field, bool add, Rng& rng) {
  const pb::Reflection* r = message->GetReflection();
  using F = pb::FieldDescriptor;
  constexpr double kNan = std::numeric_limits<double>::quiet_NaN();
  constexpr double kInf = std::numeric_limits<double>::infinity();
  switch (field->cpp_type()) {
    case F::CPPTYPE_INT32: {
      const std::int32_t v = OneOf<std::int32_t>(
          rng, {0, -1, 1, std::numeric_limits<std::int32_t>::min(),
                std::numeric_limits<std::int32_t>::max(), 1 << 20, -1000000, 4097});
      add ? r->AddInt32(message, field, v) : r->SetInt32(message, field, v);
      break;
    }
    case F::CPPTYPE_INT64: {
      const std::int64_t v =
          OneOf<std::int64_t>(rng, {0, -1, std::numeric_limits<std::int64_t>::min(),
                                    std::numeric_limits<std::int64_t>::max(), std::int64_t{1} << 50,
                                    -(std::int64_t{1} << 50)});
      add ? r->AddInt64(message, field, v) : r->SetInt64(message, field, v);
      break;
    }
    case F::CPPTYPE_UINT32: {
      const std::uint32_t v = OneOf<std::uint32_t>(
          rng,
          {0u, 1u, std::numeric_limits<std::uint32_t>::max(), 1u << 31, 4097u, 65536u, 100000u});
      add ? r->AddUInt32(message, field, v) : r->SetUInt32(message, field, v);
      break;
    }
    case F::CPPTYPE_UINT64: {
      const std::uint64_t v =
          OneOf<std::uint64_t>(rng, {0u, 1u, std::numeric_limits<std::uint64_t>::max(),
                                     std::uint64_t{1} << 63, std::uint64_t{1} << 40});
      add ? r->AddUInt64(message, field, v) : r->SetUInt64(message, field, v);
      break;
    }
    case F::CPPTYPE_DOUBLE:
    case F::CPPTYPE_FLOAT: {
      const double v =
          OneOf<double>(rng, {kNan, kInf, -kInf, -0.0, 1e308, -1e308, 5e-324, 1e15, -1e15});
      if (field->cpp_type() == F::CPPTYPE_DOUBLE)
        add ? r->AddDouble(message, field, v) : r->SetDouble(message, field, v);
      else
        add ? r->AddFloat(message, field, static_cast<float>(v))
            : r->SetFloat(message, field, static_cast<float>(v));
      break;
    }
    case F::CPPTYPE_BOOL: {
      const bool v = Pick(rng, 2) == 1;
      add ? r->AddBool(message, field, v) : r->SetBool(message, field, v);
      break;
    }
    case F::CPPTYPE_ENUM: {
      const int v = OneOf<int>(rng, {-1, 99, 1 << 30, std::numeric_limits<int>::min(),
                                     field->enum_type()->value_count()});
      add ? r->AddEnumValue(message, field, v) : r->SetEnumValue(message, field, v);
      break;
    }
    case F::CPPTYPE_STRING: {
      const std::string v = AbsurdText(rng);
      add ? r->AddString(message, field, v) : r->SetString(message, field, v);
      break;
    }
    case F::CPPTYPE_MESSAGE: {
      pb::Message* sub = add ? r->AddMessage(message, field) : r->MutableMessage(message, field);
      // Empty, or with one absurd field of its own.
      const pb::Descriptor* d = sub->GetDescriptor();
      if (d->field_count() > 0 && Pick(rng, 2) == 1) {
        const pb::FieldDescriptor* inner = d->field(Pick(rng, d->field_count()));
        SetAbsurd(sub, inner, inner->is_repeated(), rng);
      }
      break;
    }
  }
}

// Puts an absurd value into one field of `message`, chosen at random,
// descending into sub-messages; repeated fields get cleared, one, three or a
// thousand absurd elements. Returns the field's path ("" for a message
// without fields).
inline std::string MutateOneField(pb::Message* message, Rng& rng, int depth = 0) {
  const pb::Descriptor* d = message->GetDescriptor();
  if (d->field_count() == 0) return "";
  const pb::FieldDescriptor* field = d->field(Pick(rng, d->field_count()));
  const pb::Reflection* r = message->GetReflection();
  if (field->is_repeated()) {
    const int n = OneOf<int>(rng, {0, 1, 3, 1000});
    if (n == 0) {
      r->ClearField(message, field);
      return field->name() + "[cleared]";
    }
    for (int i = 0; i < n; ++i) SetAbsurd(message, field, true, rng);
    return field->name() + "[+" + std::to_string(n) + "]";
  }
  if (field->cpp_type() == pb::FieldDescriptor::CPPTYPE_MESSAGE) {
    pb::Message* sub = r->MutableMessage(message, field);
    if (depth < 4 && Pick(rng, 4) != 0 && sub->GetDescriptor()->field_count() > 0)
      return field->name() + "." + MutateOneField(sub, rng, depth + 1);
    if (Pick(rng, 2) == 0) {
      r->ClearField(message, field);
      return field->name() + "[cleared]";
    }
    sub->Clear();
    return field->name() + "[empty]";
  }
  SetAbsurd(message, field, false, rng);
  return field->name();
}

// `bytes` cut at a random point (1 .. size - 1; unchanged below 2 bytes).
inline std::string Truncated(const std::string& bytes, Rng& rng) {
  if (bytes.size() < 2) return bytes;
  return bytes.substr(0, 1 + static_cast<std::size_t>(rng() % (bytes.size() - 1)));
}

// `bytes` with 1..8 bits flipped; positions in the first 64 bytes or the
// last `tail` bytes (where the fields other than pixel data lie).
inline std::string BitFlipped(std::string bytes, Rng& rng, std::size_t tail = 1 << 16) {
  if (bytes.empty()) return bytes;
  const int flips = 1 + Pick(rng, 8);
  for (int i = 0; i < flips; ++i) {
    std::size_t at = 0;
    if (bytes.size() <= 64 + tail || Pick(rng, 2) == 0)
      at = rng() % std::min<std::size_t>(bytes.size(), 64);
    else
      at = bytes.size() - 1 - rng() % tail;
    if (Pick(rng, 4) == 0) at = rng() % bytes.size();
    bytes[at] = static_cast<char>(bytes[at] ^ (1 << Pick(rng, 8)));
  }
  return bytes;
}

}  // namespace bsls::processing::test

#endif  // BSLS_TESTS_PROCESSING_RAW_CALLS_H_
