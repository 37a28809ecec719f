// Calls every method of bsls.v1.CaptureDaemon once on the socket given as the
// first argument and prints "<method> <grpc status code>" per line. The roles
// test runs it under other uids: a code other than PERMISSION_DENIED or
// UNAUTHENTICATED means the daemon let the call through.
#include <grpcpp/grpcpp.h>

#include <chrono>
#include <cstdio>
#include <string>

#include "bsls/v1/capture.grpc.pb.h"

namespace {

using bsls::v1::CaptureDaemon;

std::unique_ptr<grpc::ClientContext> Context(int ms = 5000) {
  auto context = std::make_unique<grpc::ClientContext>();
  context->set_deadline(std::chrono::system_clock::now() + std::chrono::milliseconds(ms));
  return context;
}

void Print(const char* method, const grpc::Status& status) {
  std::printf("%s %d\n", method, static_cast<int>(status.error_code()));
}

// The status of a server stream after its first message (or its end).
template <typename Reader, typename Message>
grpc::Status FirstOf(grpc::ClientContext* context, Reader reader) {
  Message message;
  if (reader->Read(&message)) {
    context->TryCancel();
    while (reader->Read(&message)) {
    }
    reader->Finish().IgnoreError();
    return grpc::Status::OK;  // a message arrived: the call was let through
  }
  return reader->Finish();
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: role_probe SOCKET\n");
    return 2;
  }
  auto stub = CaptureDaemon::NewStub(
      grpc::CreateChannel(std::string("unix:") + argv[1], grpc::InsecureChannelCredentials()));
  {
    bsls::v1::DeviceStatus reply;
    Print("GetStatus", stub->GetStatus(Context().get(), {}, &reply));
  }
  {
    bsls::v1::SelectCameraRequest request;
    request.set_camera(bsls::v1::CAMERA_LEFT);
    bsls::v1::DeviceStatus reply;
    Print("SelectCamera", stub->SelectCamera(Context().get(), request, &reply));
  }
  {
    bsls::v1::SetGainRequest request;
    request.set_gain(128);
    bsls::v1::DeviceStatus reply;
    Print("SetGain", stub->SetGain(Context().get(), request, &reply));
  }
  {
    auto context = Context(10000);
    Print("StreamPreview",
          FirstOf<decltype(stub->StreamPreview(context.get(), {})), bsls::v1::PreviewFrame>(
              context.get(), stub->StreamPreview(context.get(), {})));
  }
  {
    bsls::v1::GrabRequest request;
    request.set_side(bsls::v1::GRAB_SIDE_LEFT);
    request.set_session_id("role-probe");
    bsls::v1::GrabResponse reply;
    Print("Grab", stub->Grab(Context(30000).get(), request, &reply));
  }
  {
    bsls::v1::ListCapturesResponse reply;
    Print("ListCaptures", stub->ListCaptures(Context().get(), {}, &reply));
  }
  {
    bsls::v1::GetCaptureRequest request;
    request.set_capture_id(std::string(32, '0'));
    bsls::v1::CaptureInfo reply;
    Print("GetCapture", stub->GetCapture(Context().get(), request, &reply));
  }
  {
    bsls::v1::DeleteCaptureRequest request;
    request.set_capture_id(std::string(32, '0'));
    bsls::v1::DeleteCaptureResponse reply;
    Print("DeleteCapture", stub->DeleteCapture(Context().get(), request, &reply));
  }
  {
    bsls::v1::SlideState reply;
    Print("GetSlideState", stub->GetSlideState(Context().get(), {}, &reply));
  }
  {
    bsls::v1::SetSlideRequest request;
    request.set_slide(2);
    bsls::v1::SlideState reply;
    Print("SetSlide", stub->SetSlide(Context(20000).get(), request, &reply));
  }
  {
    bsls::v1::SetFocusRequest request;
    request.set_steps(1);
    bsls::v1::SlideState reply;
    Print("SetFocus", stub->SetFocus(Context().get(), request, &reply));
  }
  {
    bsls::v1::SetLampRequest request;
    request.set_on(true);
    bsls::v1::SlideState reply;
    Print("SetLamp", stub->SetLamp(Context().get(), request, &reply));
  }
  {
    // Events come only when something happens: a deadline after the stream
    // opened means the call was let through.
    auto context = Context(1000);
    auto reader = stub->WatchEvents(context.get(), {});
    bsls::v1::Event event;
    while (reader->Read(&event)) {
    }
    Print("WatchEvents", reader->Finish());
  }
  return 0;
}
