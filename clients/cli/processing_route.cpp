#include "processing_route.h"

#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <filesystem>

#include "bsls/common/atomic_file.h"
#include "bsls/rpc/tls.h"

#ifndef BSLS_VERSION
#define BSLS_VERSION "unknown"
#endif

namespace bsls::cli {
namespace {

// The service in this process: one job at a time (the command's), frames as
// large as a request message carries.
processing::ProcessingServiceOptions LocalServiceOptions() {
  processing::ProcessingServiceOptions options;
  options.workers = 1;
  options.queue = 0;
  options.replica = "local";
  options.software_version = BSLS_VERSION;
  options.max_frame_pixels = kMaxLocalFramePixels;
  return options;
}

}  // namespace

ProcessingRoute::ProcessingRoute(const ServiceAddress& address) : address_(address) {
  processing::ClientOptions options;
  options.timeout = std::chrono::milliseconds(static_cast<long>(address.timeout_s * 1000));
  if (address.target.empty()) {
    // No retries here: a refusal in this process is no replica's passing state.
    options.attempts = 1;
    service_ = std::make_unique<processing::ProcessingService>(LocalServiceOptions());
    grpc::ServerBuilder builder;
    builder.SetMaxReceiveMessageSize(processing::kMaxRequestMessageBytes);
    builder.SetMaxSendMessageSize(processing::kMaxReplyMessageBytes);
    builder.RegisterService(service_.get());
    server_ = builder.BuildAndStart();
    if (!server_) throw CommandError(kExitServiceFailed, "the processing service did not start");
    grpc::ChannelArguments args = processing::ProcessingChannelArguments();
    client_ =
        std::make_unique<processing::ProcessingClient>(server_->InProcessChannel(args), options);
    return;
  }
  options.target = address.target;
  options.tls = TlsOf(address);
  if (!rpc::IsUnixTarget(address.target) && !rpc::IsLoopbackTarget(address.target) &&
      !options.tls.complete())
    throw CommandError(kExitUsage, "--server " + address.target +
                                       " is another machine, which is mutual TLS only: give "
                                       "--tls-ca, --tls-cert and --tls-key");
  try {
    client_ = std::make_unique<processing::ProcessingClient>(
        processing::OpenProcessingChannel(options), options);
  } catch (const rpc::TlsFileError& e) {
    throw CommandError(kExitInput, e.what());
  }
}

ProcessingRoute::~ProcessingRoute() {
  client_.reset();
  if (server_) server_->Shutdown();
}

processing::ProgressCallback ProcessingRoute::Progress(bool quiet) const {
  return ProgressPrinter(quiet || (local() && ::isatty(STDERR_FILENO) == 0));
}

void ProcessingRoute::Check(const grpc::Status& status, const std::string& what) const {
  CheckWork(status, what, address_);
}

void WriteSurfaceArtifact(const std::string& path, const std::map<std::string, std::string>& files,
                          const std::string& name) {
  const std::string& bytes = files.at(name);
  std::string extension = std::filesystem::path(path).extension().string();
  std::transform(extension.begin(), extension.end(), extension.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  if (extension == ".ply") {
    WriteFileAtomically(path, bytes);
    return;
  }
  try {
    io::WriteSurface(path, io::DecodePly(bytes, name));
  } catch (const std::invalid_argument& e) {
    throw CommandError(kExitUsage, e.what());
  }
}

}  // namespace bsls::cli
