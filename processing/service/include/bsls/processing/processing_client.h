// The C++ client of the processing service, shared by `bsls`, bslsd's
// processing queue, the tests and the benchmark. One channel reaches one or
// several replicas through gRPC's own round_robin load balancing (a target
// such as "ipv4:127.0.0.1:7001,127.0.0.1:7002" or "dns:///processd:7000");
// a work call that fails with UNAVAILABLE or RESOURCE_EXHAUSTED before its
// result is retried (after a short back-off), which round_robin sends to
// the next replica.
//
// Work calls gather the streamed artifacts (checked: order, size, SHA-256)
// and return them with the Result; progress goes to an optional callback.
//
// Thread-safety: a ProcessingClient may be used from several threads at once
// (it is neither copyable nor movable: hold it by pointer to share it).
#ifndef BSLS_PROCESSING_PROCESSING_CLIENT_H_
#define BSLS_PROCESSING_PROCESSING_CLIENT_H_

#include <grpcpp/grpcpp.h>

#include <chrono>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <set>
#include <string>
#include <vector>

#include "bsls/rpc/tls.h"
#include "bsls/v1/processing.grpc.pb.h"

namespace bsls::processing {

struct ClientOptions {
  // "unix:PATH", "host:port", "ipv4:a:p,b:p" or "dns:///name:port".
  std::string target;
  // Mutual TLS when complete; plain otherwise (a Unix socket or loopback).
  rpc::TlsFiles tls;
  std::chrono::milliseconds timeout{120000};  // deadline of each attempt
  int attempts = 4;                           // tries of a work call, >= 1
  std::chrono::milliseconds backoff{100};     // before the 2nd try, doubled after
};

// The message caps of the contracts: a request holds at most two 4096^2
// frames; replies are cut into 1 MiB chunks.
constexpr int kMaxRequestMessageBytes = 40 << 20;
constexpr int kMaxReplyMessageBytes = 8 << 20;

// A client's channel arguments with those caps.
grpc::ChannelArguments ProcessingChannelArguments();

// A channel to the service with round_robin balancing and the message caps
// of the contracts. Throws rpc::TlsFileError for unusable TLS files and
// std::invalid_argument for plain TCP to an address that is not loopback.
std::shared_ptr<grpc::Channel> OpenProcessingChannel(const ClientOptions& options);

// What a work call gave.
struct WorkOutcome {
  grpc::Status status;
  v1::Result result;  // set when status is OK
  // Artifacts by name: all of them when OK; those sent whole before a
  // refusal otherwise (ProcessFrame's skeleton.png).
  std::map<std::string, std::string> files;
  int attempts = 0;  // tries made
};

using ProgressCallback = std::function<void(const v1::Progress&)>;

// One file of a calibration upload: its path relative to the manifest's
// folder and its bytes.
struct UploadFile {
  std::string path;
  std::string bytes;
};

class ProcessingClient {
 public:
  ProcessingClient(std::shared_ptr<grpc::Channel> channel, ClientOptions options);
  ProcessingClient(const ProcessingClient&) = delete;
  ProcessingClient& operator=(const ProcessingClient&) = delete;

  // ProcessFrame (see processing.proto), with retries.
  WorkOutcome ProcessFrame(const v1::ProcessFrameRequest& request,
                           const ProgressCallback& progress = {});
  // ReconstructSession, with retries.
  WorkOutcome ReconstructSession(const v1::ReconstructSessionRequest& request,
                                 const ProgressCallback& progress = {});
  // Measure, with retries.
  WorkOutcome Measure(const v1::MeasureRequest& request, const ProgressCallback& progress = {});
  // Calibrate: the manifest, then every file in 1 MiB chunks; with retries.
  WorkOutcome Calibrate(const std::string& manifest_yaml, const std::vector<UploadFile>& files,
                        const std::string& request_tag = "", const ProgressCallback& progress = {});
  // PutCalibration (no retry: it is quick; the caller decides).
  grpc::Status PutCalibration(const std::string& yaml, v1::CalibrationInfo* info);
  // GetServerInfo of whichever replica answers.
  grpc::Status GetServerInfo(v1::ServerInfo* info);

  // Cancels every call under way and makes later calls fail CANCELLED at
  // once (shutdown).
  void CancelAll();

  // A CalibrationSource carrying the file itself, which any replica can use
  // (it caches it on the way).
  static v1::CalibrationSource Inline(const std::string& yaml);

 private:
  using Attempt = std::function<grpc::Status(grpc::ClientContext*, WorkOutcome*)>;
  WorkOutcome WithRetries(const Attempt& attempt);
  std::unique_ptr<grpc::ClientContext> Context() const;

  std::shared_ptr<grpc::Channel> channel_;
  std::unique_ptr<v1::Processing::Stub> stub_;
  ClientOptions options_;
  std::mutex mutex_;
  std::set<grpc::ClientContext*> live_;  // contexts of calls under way
  bool cancelled_ = false;
};

// True for the statuses a retry (on another replica) may cure.
bool IsRetryable(const grpc::Status& status);

}  // namespace bsls::processing

#endif  // BSLS_PROCESSING_PROCESSING_CLIENT_H_
