// The gRPC service of bslsd (proto/bsls/v1/capture.proto): authorises each
// call by the caller's role, validates every field, runs device work on the
// capture thread (CaptureDevice), stores grabs durably (CaptureStore) before
// acknowledging them, drives the slide controller, and streams previews and
// events. Errors of the layers below map one to one onto gRPC status codes;
// every message names the field or the thing and the reason.
//
// The preview and event streams run on gRPC's callback API: an open stream
// holds no thread, only its newest message and one write in flight.
//
// Thread-safety: gRPC calls the handlers from its thread pool; every member
// is safe to call concurrently.
#ifndef BSLS_SERVICE_CAPTURE_SERVICE_H_
#define BSLS_SERVICE_CAPTURE_SERVICE_H_

#include <atomic>
#include <chrono>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <utility>

#include "bsls/common/status.h"
#include "bsls/service/capture_device.h"
#include "bsls/service/event_hub.h"
#include "bsls/service/processing_queue.h"
#include "bsls/service/roles.h"
#include "bsls/service/stalled_writes.h"
#include "bsls/service/unix_listener.h"
#include "bsls/slides/slide_controller.h"
#include "bsls/store/capture_store.h"
#include "bsls/v1/capture.grpc.pb.h"

namespace bsls::service {

// Limits that keep one caller from exhausting the daemon.
struct ServiceLimits {
  int max_preview_streams = 8;
  int max_event_streams = 16;
  // Deadline given to calls that come without one (other clients than ours).
  std::chrono::milliseconds default_deadline{10000};
  // Longest deadline honoured for a grab or slide change.
  std::chrono::milliseconds max_deadline{60000};
  // A stream message (preview frame, event, result chunk) that the caller
  // does not take within this ends its stream with RESOURCE_EXHAUSTED: a
  // reader that reads nothing gives back its slot.
  std::chrono::milliseconds stream_write_timeout{10000};
};

// The grpc::StatusCode of a layer error code.
grpc::StatusCode ToGrpcCode(ErrorCode code);
// A grpc::Status carrying `status`'s code and message.
grpc::Status ToGrpc(const Status& status);

namespace internal {
class PushControl;
template <typename Message>
class PushStream;
}  // namespace internal

class CaptureService final
    : public v1::CaptureDaemon::WithCallbackMethod_StreamPreview<
          v1::CaptureDaemon::WithCallbackMethod_WatchEvents<v1::CaptureDaemon::Service>> {
 public:
  // Everything is borrowed and must outlive the service; `slides` may be
  // nullptr (no slide controller configured: slide calls fail UNAVAILABLE),
  // `processing` too (captures are then reported STATE_DISABLED).
  CaptureService(CaptureDevice* device, store::CaptureStore* store, slides::SlideController* slides,
                 EventHub* events, const PeerRegistry* peers, const RolePolicy* policy,
                 ServiceLimits limits, std::string software_version,
                 ProcessingQueue* processing = nullptr);

  // From now on new calls that change anything fail UNAVAILABLE ("shutting
  // down") and open streams end; calls under way finish.
  void BeginDrain();
  // Grabs acknowledged (stored) since start.
  std::uint64_t grabs_acknowledged() const { return grabs_acknowledged_; }

  grpc::Status GetStatus(grpc::ServerContext* context, const v1::GetStatusRequest* request,
                         v1::DeviceStatus* reply) override;
  grpc::Status SelectCamera(grpc::ServerContext* context, const v1::SelectCameraRequest* request,
                            v1::DeviceStatus* reply) override;
  grpc::Status SetGain(grpc::ServerContext* context, const v1::SetGainRequest* request,
                       v1::DeviceStatus* reply) override;
  grpc::ServerWriteReactor<v1::PreviewFrame>* StreamPreview(
      grpc::CallbackServerContext* context, const v1::PreviewRequest* request) override;
  grpc::Status Grab(grpc::ServerContext* context, const v1::GrabRequest* request,
                    v1::GrabResponse* reply) override;
  grpc::Status ListCaptures(grpc::ServerContext* context, const v1::ListCapturesRequest* request,
                            v1::ListCapturesResponse* reply) override;
  grpc::Status GetCapture(grpc::ServerContext* context, const v1::GetCaptureRequest* request,
                          v1::CaptureInfo* reply) override;
  grpc::Status GetCaptureResult(grpc::ServerContext* context,
                                const v1::GetCaptureResultRequest* request,
                                grpc::ServerWriter<v1::Artifact>* writer) override;
  grpc::Status DeleteCapture(grpc::ServerContext* context, const v1::DeleteCaptureRequest* request,
                             v1::DeleteCaptureResponse* reply) override;
  grpc::Status GetSlideState(grpc::ServerContext* context, const v1::GetSlideStateRequest* request,
                             v1::SlideState* reply) override;
  grpc::Status SetSlide(grpc::ServerContext* context, const v1::SetSlideRequest* request,
                        v1::SlideState* reply) override;
  grpc::Status SetFocus(grpc::ServerContext* context, const v1::SetFocusRequest* request,
                        v1::SlideState* reply) override;
  grpc::Status SetLamp(grpc::ServerContext* context, const v1::SetLampRequest* request,
                       v1::SlideState* reply) override;
  grpc::ServerWriteReactor<v1::Event>* WatchEvents(grpc::CallbackServerContext* context,
                                                   const v1::WatchEventsRequest* request) override;

 private:
  // OK with the caller filled in, or UNAUTHENTICATED / PERMISSION_DENIED.
  grpc::Status Authorize(const grpc::ServerContextBase* context, std::string_view method,
                         Caller* caller);
  // The call's deadline on the steady clock, capped; the default when none.
  Clock::time_point Deadline(const grpc::ServerContextBase* context) const;
  // The preview stream's checks: OK, or why it is refused.
  grpc::Status AdmitPreview(grpc::CallbackServerContext* context,
                            const v1::PreviewRequest& request);
  // A push stream named `what` on `context`, listed for the drain until it
  // ends, when it also gives back its place in `slots`; connect its source,
  // then wake it. Ended at once when a drain has begun.
  template <typename Message>
  std::pair<internal::PushStream<Message>*, std::shared_ptr<internal::PushControl>> OpenStream(
      grpc::CallbackServerContext* context, const char* what, std::atomic<int>* slots,
      bool send_initial_metadata = false);
  void FillStatus(const Caller& caller, v1::DeviceStatus* reply);
  void FillSlideState(v1::SlideState* reply) const;
  // The capture's metadata and its processing status.
  void FillCapture(const store::CaptureInfo& info, v1::CaptureInfo* reply);

  CaptureDevice* device_;
  store::CaptureStore* store_;
  slides::SlideController* slides_;
  EventHub* events_;
  const PeerRegistry* peers_;
  const RolePolicy* policy_;
  ServiceLimits limits_;
  std::string software_version_;
  ProcessingQueue* processing_;
  std::atomic<bool> draining_{false};
  std::atomic<int> preview_streams_{0};
  std::atomic<int> event_streams_{0};
  std::atomic<std::uint64_t> grabs_acknowledged_{0};
  std::mutex streams_mutex_;
  std::map<std::uint64_t, std::shared_ptr<internal::PushControl>> streams_;  // open push streams
  std::uint64_t next_stream_ = 0;
  StalledWrites stalled_writes_;  // last: its thread stops first
};

}  // namespace bsls::service

#endif  // BSLS_SERVICE_CAPTURE_SERVICE_H_
