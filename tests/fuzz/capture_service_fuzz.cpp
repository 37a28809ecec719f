// libFuzzer target over bslsd's request handlers: bslsd's own assembly
// (bslsd::Daemon) in-process -- the real CaptureService behind the real
// Unix-socket front door (SO_PEERCRED, the fuzzer's uid as admin), the
// simulated framestore, the emulated slide mechanism and a store in a
// temporary directory. Byte 0 picks the call; the remaining bytes are its
// request message in protobuf wire format (arbitrary: what fails to parse is
// sent as an empty request). No input may crash the daemon, hang it past
// the call deadline, leak, or lose a stored capture.
#include <grpcpp/grpcpp.h>
#include <spdlog/spdlog.h>
#include <unistd.h>

#include <chrono>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <memory>
#include <string>

#include "daemon.h"

namespace {

using namespace bsls;

// The daemon (bslsd's own assembly, in-process) and a client, on the first input.
struct Fixture {
  std::filesystem::path dir;
  std::unique_ptr<bslsd::Daemon> daemon;
  std::unique_ptr<v1::CaptureDaemon::Stub> stub;
};

Fixture& Instance() {
  static Fixture* fixture = [] {
    auto* f = new Fixture;
    char pattern[] = "/tmp/bsls_service_fuzz_XXXXXX";
    f->dir = ::mkdtemp(pattern);
    bslsd::Config config = bslsd::DefaultConfig();
    config.log_level = "off";
    config.store.root = (f->dir / "store").string();
    config.store.free_space_reserve_bytes = 16u << 20;
    config.store.retention.max_total_bytes = 8u << 20;  // applied after each input
    config.framestore.simulated_breathing_mm = 0.0;
    config.listen.unix_socket = (f->dir / "bslsd.sock").string();
    config.roles.members[service::Role::kAdmin] = {std::to_string(::geteuid())};
    slides::SlideControllerConfig& slides = config.slides.controller;
    slides.pulse = std::chrono::milliseconds(2);
    slides.settle = std::chrono::milliseconds(5);
    slides.emulated_travel = std::chrono::milliseconds(5);
    slides.focus_step = std::chrono::milliseconds(1);
    config.limits.max_preview_streams = 2;
    config.limits.default_deadline = std::chrono::milliseconds(500);
    config.limits.max_deadline = std::chrono::milliseconds(2000);
    spdlog::set_level(spdlog::level::off);
    auto started = bslsd::Daemon::Start(config, {});
    if (!started.ok()) {
      std::fprintf(stderr, "capture_service_fuzz: %s\n", started.status().ToString().c_str());
      std::abort();
    }
    f->daemon = std::move(started).value();
    f->stub = v1::CaptureDaemon::NewStub(grpc::CreateChannel("unix:" + config.listen.unix_socket,
                                                             grpc::InsecureChannelCredentials()));
    // The fuzzer exits without destructors; the temporary directory goes with it.
    std::atexit([] { std::filesystem::remove_all(Instance().dir); });
    return f;
  }();
  return *fixture;
}

std::unique_ptr<grpc::ClientContext> Context() {
  auto context = std::make_unique<grpc::ClientContext>();
  context->set_deadline(std::chrono::system_clock::now() + std::chrono::milliseconds(1500));
  return context;
}

template <typename Request>
Request Parse(const std::uint8_t* data, std::size_t size) {
  Request request;
  if (!request.ParseFromArray(data, static_cast<int>(size))) request.Clear();
  return request;
}

// Reads at most `n` messages of a server stream, then cancels it.
template <typename Reader, typename Message>
void Drain(grpc::ClientContext* context, Reader reader, int n) {
  Message message;
  for (int i = 0; i < n && reader->Read(&message); ++i) {
  }
  context->TryCancel();
  while (reader->Read(&message)) {
  }
  reader->Finish().IgnoreError();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size < 1) return 0;
  Fixture& d = Instance();
  const std::uint8_t* body = data + 1;
  const std::size_t n = size - 1;
  auto context = Context();
  switch (data[0] % 13) {
    case 0: {
      v1::DeviceStatus reply;
      d.stub->GetStatus(context.get(), Parse<v1::GetStatusRequest>(body, n), &reply).IgnoreError();
      break;
    }
    case 1: {
      v1::DeviceStatus reply;
      d.stub->SelectCamera(context.get(), Parse<v1::SelectCameraRequest>(body, n), &reply)
          .IgnoreError();
      break;
    }
    case 2: {
      v1::DeviceStatus reply;
      d.stub->SetGain(context.get(), Parse<v1::SetGainRequest>(body, n), &reply).IgnoreError();
      break;
    }
    case 3: {
      auto reader = d.stub->StreamPreview(context.get(), Parse<v1::PreviewRequest>(body, n));
      Drain<decltype(reader), v1::PreviewFrame>(context.get(), std::move(reader), 2);
      break;
    }
    case 4: {
      v1::GrabResponse reply;
      d.stub->Grab(context.get(), Parse<v1::GrabRequest>(body, n), &reply).IgnoreError();
      break;
    }
    case 5: {
      v1::ListCapturesResponse reply;
      d.stub->ListCaptures(context.get(), Parse<v1::ListCapturesRequest>(body, n), &reply)
          .IgnoreError();
      break;
    }
    case 6: {
      v1::CaptureInfo reply;
      d.stub->GetCapture(context.get(), Parse<v1::GetCaptureRequest>(body, n), &reply)
          .IgnoreError();
      break;
    }
    case 7: {
      v1::DeleteCaptureResponse reply;
      d.stub->DeleteCapture(context.get(), Parse<v1::DeleteCaptureRequest>(body, n), &reply)
          .IgnoreError();
      break;
    }
    case 8: {
      v1::SlideState reply;
      d.stub->GetSlideState(context.get(), Parse<v1::GetSlideStateRequest>(body, n), &reply)
          .IgnoreError();
      break;
    }
    case 9: {
      v1::SlideState reply;
      d.stub->SetSlide(context.get(), Parse<v1::SetSlideRequest>(body, n), &reply).IgnoreError();
      break;
    }
    case 10: {
      v1::SlideState reply;
      d.stub->SetFocus(context.get(), Parse<v1::SetFocusRequest>(body, n), &reply).IgnoreError();
      break;
    }
    case 11: {
      v1::SlideState reply;
      d.stub->SetLamp(context.get(), Parse<v1::SetLampRequest>(body, n), &reply).IgnoreError();
      break;
    }
    case 12: {
      context->set_deadline(std::chrono::system_clock::now() + std::chrono::milliseconds(50));
      auto reader = d.stub->WatchEvents(context.get(), Parse<v1::WatchEventsRequest>(body, n));
      Drain<decltype(reader), v1::Event>(context.get(), std::move(reader), 4);
      break;
    }
  }
  d.daemon->ApplyRetention();
  return 0;
}
