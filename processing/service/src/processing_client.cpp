#include "bsls/processing/processing_client.h"

#include <stdexcept>
#include <thread>

#include "bsls/rpc/artifacts.h"

namespace bsls::processing {
namespace {

// Reads a work call's stream into `out`: progress to the callback, artifacts
// assembled, the result kept. A stream that ends OK without a result or
// with an unfinished artifact is DATA_LOSS.
// `before_finish` runs when the stream has ended, before its status is taken.
template <typename Reader>
grpc::Status ReadWork(Reader* reader, const ProgressCallback& progress, WorkOutcome* out,
                      const std::function<void()>& before_finish = {}) {
  rpc::ArtifactAssembler artifacts;
  v1::WorkEvent event;
  bool have_result = false;
  std::string damage;
  while (reader->Read(&event)) {
    switch (event.event_case()) {
      case v1::WorkEvent::kProgress:
        if (progress) progress(event.progress());
        break;
      case v1::WorkEvent::kArtifact:
        if (damage.empty()) try {
            artifacts.Add(event.artifact());
          } catch (const rpc::ArtifactError& e) {
            damage = e.what();
          }
        break;
      case v1::WorkEvent::kResult:
        out->result = event.result();
        have_result = true;
        break;
      default:
        break;
    }
  }
  if (before_finish) before_finish();
  grpc::Status status = reader->Finish();
  if (!status.ok()) {
    // What was sent whole before a refusal (a skeleton that shows why).
    if (damage.empty()) out->files = artifacts.files();
    return status;
  }
  if (!damage.empty()) return grpc::Status(grpc::StatusCode::DATA_LOSS, damage);
  if (!have_result || !artifacts.Unfinished().empty())
    return grpc::Status(
        grpc::StatusCode::DATA_LOSS,
        "the reply ended without its result" +
            (artifacts.Unfinished().empty() ? std::string()
                                            : " (unfinished: " + artifacts.Unfinished() + ")"));
  out->files = artifacts.files();
  return status;
}

}  // namespace

bool IsRetryable(const grpc::Status& status) {
  return status.error_code() == grpc::StatusCode::UNAVAILABLE ||
         status.error_code() == grpc::StatusCode::RESOURCE_EXHAUSTED;
}

grpc::ChannelArguments ProcessingChannelArguments() {
  grpc::ChannelArguments args;
  args.SetMaxReceiveMessageSize(kMaxReplyMessageBytes);
  args.SetMaxSendMessageSize(kMaxRequestMessageBytes);
  return args;
}

std::shared_ptr<grpc::Channel> OpenProcessingChannel(const ClientOptions& options) {
  grpc::ChannelArguments args = ProcessingChannelArguments();
  args.SetLoadBalancingPolicyName("round_robin");
  // A replica that went away is tried again soon after it comes back.
  args.SetInt(GRPC_ARG_INITIAL_RECONNECT_BACKOFF_MS, 200);
  args.SetInt(GRPC_ARG_MAX_RECONNECT_BACKOFF_MS, 2000);
  if (options.tls.complete()) {
    // A list of addresses has no one host name: the certificate is checked
    // against the first address's host (replicas share one name).
    const std::string name = rpc::TlsServerName(options.target);
    if (!name.empty()) args.SetSslTargetNameOverride(name);
    return grpc::CreateCustomChannel(options.target, rpc::MutualTlsChannelCredentials(options.tls),
                                     args);
  }
  if (!rpc::IsUnixTarget(options.target) && !rpc::IsLoopbackTarget(options.target))
    throw std::invalid_argument(options.target +
                                ": a remote processing service is mutual TLS only: give the CA, "
                                "certificate and key files");
  return grpc::CreateCustomChannel(options.target, grpc::InsecureChannelCredentials(), args);
}

ProcessingClient::ProcessingClient(std::shared_ptr<grpc::Channel> channel, ClientOptions options)
    : channel_(std::move(channel)),
      stub_(v1::Processing::NewStub(channel_)),
      options_(std::move(options)) {}

v1::CalibrationSource ProcessingClient::Inline(const std::string& yaml) {
  v1::CalibrationSource source;
  source.set_yaml(yaml);
  return source;
}

std::unique_ptr<grpc::ClientContext> ProcessingClient::Context() const {
  auto context = std::make_unique<grpc::ClientContext>();
  context->set_deadline(std::chrono::system_clock::now() + options_.timeout);
  return context;
}

void ProcessingClient::CancelAll() {
  std::lock_guard lock(mutex_);
  cancelled_ = true;
  for (grpc::ClientContext* context : live_) context->TryCancel();
}

WorkOutcome ProcessingClient::WithRetries(const Attempt& attempt) {
  WorkOutcome out;
  auto backoff = options_.backoff;
  for (int i = 1; i <= std::max(1, options_.attempts); ++i) {
    out = WorkOutcome{};
    out.attempts = i;
    const std::unique_ptr<grpc::ClientContext> context = Context();
    {
      std::lock_guard lock(mutex_);
      if (cancelled_) {
        out.status = grpc::Status(grpc::StatusCode::CANCELLED, "the client was stopped");
        break;
      }
      live_.insert(context.get());
    }
    out.status = attempt(context.get(), &out);
    {
      std::lock_guard lock(mutex_);
      live_.erase(context.get());
    }
    if (out.status.ok() || !IsRetryable(out.status) || i == options_.attempts) break;
    std::this_thread::sleep_for(backoff);
    backoff *= 2;
  }
  return out;
}

WorkOutcome ProcessingClient::ProcessFrame(const v1::ProcessFrameRequest& request,
                                           const ProgressCallback& progress) {
  return WithRetries([&](grpc::ClientContext* context, WorkOutcome* out) {
    auto reader = stub_->ProcessFrame(context, request);
    return ReadWork(reader.get(), progress, out);
  });
}

WorkOutcome ProcessingClient::ReconstructSession(const v1::ReconstructSessionRequest& request,
                                                 const ProgressCallback& progress) {
  return WithRetries([&](grpc::ClientContext* context, WorkOutcome* out) {
    auto reader = stub_->ReconstructSession(context, request);
    return ReadWork(reader.get(), progress, out);
  });
}

WorkOutcome ProcessingClient::Measure(const v1::MeasureRequest& request,
                                      const ProgressCallback& progress) {
  return WithRetries([&](grpc::ClientContext* context, WorkOutcome* out) {
    auto reader = stub_->Measure(context, request);
    return ReadWork(reader.get(), progress, out);
  });
}

WorkOutcome ProcessingClient::Calibrate(const std::string& manifest_yaml,
                                        const std::vector<UploadFile>& files,
                                        const std::string& request_tag,
                                        const ProgressCallback& progress) {
  return WithRetries([&](grpc::ClientContext* context, WorkOutcome* out) {
    auto stream = stub_->Calibrate(context);
    // The upload runs beside the reading of events (a bidirectional stream).
    std::thread writer([&] {
      v1::CalibrateRequest part;
      part.mutable_manifest()->set_yaml(manifest_yaml);
      part.mutable_manifest()->set_request_tag(request_tag);
      bool ok = stream->Write(part);
      for (const UploadFile& file : files) {
        std::size_t offset = 0;
        do {
          const std::size_t n = std::min(rpc::kArtifactChunkBytes, file.bytes.size() - offset);
          part.Clear();
          v1::FileChunk* chunk = part.mutable_file();
          chunk->set_path(file.path);
          chunk->set_offset(offset);
          chunk->set_data(file.bytes.data() + offset, n);
          offset += n;
          chunk->set_last(offset == file.bytes.size());
          ok = ok && stream->Write(part);
        } while (ok && offset < file.bytes.size());
      }
      stream->WritesDone();
    });
    return ReadWork(stream.get(), progress, out, [&writer] { writer.join(); });
  });
}

grpc::Status ProcessingClient::PutCalibration(const std::string& yaml, v1::CalibrationInfo* info) {
  v1::PutCalibrationRequest request;
  request.set_yaml(yaml);
  return stub_->PutCalibration(Context().get(), request, info);
}

grpc::Status ProcessingClient::GetServerInfo(v1::ServerInfo* info) {
  return stub_->GetServerInfo(Context().get(), v1::GetServerInfoRequest{}, info);
}

}  // namespace bsls::processing
