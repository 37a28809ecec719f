#include "bsls/service/capture_service.h"

#include <grpcpp/grpcpp.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <tuple>
#include <utility>
#include <vector>

#include "bsls/rpc/artifacts.h"
#include "bsls/service/contract_messages.h"
#include "push_stream.h"

namespace bsls::service {

using framestore::Camera;

grpc::StatusCode ToGrpcCode(ErrorCode code) {
  switch (code) {
    case ErrorCode::kOk:
      return grpc::StatusCode::OK;
    case ErrorCode::kInvalidArgument:
      return grpc::StatusCode::INVALID_ARGUMENT;
    case ErrorCode::kFailedPrecondition:
      return grpc::StatusCode::FAILED_PRECONDITION;
    case ErrorCode::kPermissionDenied:
      return grpc::StatusCode::PERMISSION_DENIED;
    case ErrorCode::kUnavailable:
      return grpc::StatusCode::UNAVAILABLE;
    case ErrorCode::kDeadlineExceeded:
      return grpc::StatusCode::DEADLINE_EXCEEDED;
    case ErrorCode::kDataLoss:
      return grpc::StatusCode::DATA_LOSS;
    case ErrorCode::kNotFound:
      return grpc::StatusCode::NOT_FOUND;
    case ErrorCode::kAlreadyExists:
      return grpc::StatusCode::ALREADY_EXISTS;
    case ErrorCode::kResourceExhausted:
      return grpc::StatusCode::RESOURCE_EXHAUSTED;
    case ErrorCode::kInternal:
      return grpc::StatusCode::INTERNAL;
  }
  return grpc::StatusCode::INTERNAL;
}

grpc::Status ToGrpc(const Status& status) {
  if (status.ok()) return grpc::Status::OK;
  return {ToGrpcCode(status.code()), status.message()};
}

namespace {

constexpr std::string_view kMethodPrefix = "/bsls.v1.CaptureDaemon/";

grpc::Status Invalid(const std::string& message) {
  return {grpc::StatusCode::INVALID_ARGUMENT, message};
}

grpc::Status Draining() {
  return {grpc::StatusCode::UNAVAILABLE, "bslsd is shutting down; retry on the next daemon"};
}

// A text field within the store's limit, else the field named.
grpc::Status CheckText(const std::string& value, const char* field) {
  if (value.size() > store::kMaxTextField)
    return Invalid(std::string(field) + " is " + std::to_string(value.size()) + " bytes; at most " +
                   std::to_string(store::kMaxTextField) + " are accepted");
  return grpc::Status::OK;
}

}  // namespace

CaptureService::CaptureService(CaptureDevice* device, store::CaptureStore* store,
                               slides::SlideController* slides, EventHub* events,
                               const PeerRegistry* peers, const RolePolicy* policy,
                               ServiceLimits limits, std::string software_version,
                               ProcessingQueue* processing)
    : device_(device),
      store_(store),
      slides_(slides),
      events_(events),
      peers_(peers),
      policy_(policy),
      limits_(limits),
      software_version_(std::move(software_version)),
      processing_(processing),
      stalled_writes_(limits.stream_write_timeout) {}

void CaptureService::FillCapture(const store::CaptureInfo& info, v1::CaptureInfo* reply) {
  FillInfo(info, reply);
  Result<std::optional<store::ProcessingRecord>> record = store_->Processing(info.id.str());
  if (record.ok())
    FillProcessingStatus(*record, processing_ != nullptr && processing_->enabled(),
                         reply->mutable_processing());
  else
    reply->mutable_processing()->set_last_error(record.status().message());
}

grpc::Status CaptureService::Authorize(const grpc::ServerContextBase* context,
                                       std::string_view method, Caller* caller) {
  const std::string full = std::string(kMethodPrefix) + std::string(method);
  // Every connection was accepted by the daemon itself and its caller
  // recorded: by uid on the Unix socket, by verified client certificate on TCP.
  const std::optional<Caller> found = peers_->Find(context->peer());
  if (!found)
    return {grpc::StatusCode::UNAUTHENTICATED,
            "bslsd cannot tell who is calling on " + context->peer() +
                ": connect through the daemon's Unix socket or with a client certificate"};
  *caller = *found;
  const Role needed = RequiredRole(full);
  if (caller->role < needed) {
    spdlog::warn("refused {} to {}: needs role {}", method, caller->Describe(), ToString(needed));
    return {grpc::StatusCode::PERMISSION_DENIED, std::string(method) + " needs the " +
                                                     std::string(ToString(needed)) + " role; " +
                                                     caller->Describe() + " does not have it"};
  }
  return grpc::Status::OK;
}

Clock::time_point CaptureService::Deadline(const grpc::ServerContextBase* context) const {
  const Clock::time_point now = Clock::now();
  if (context->deadline() == std::chrono::system_clock::time_point::max())
    return now + limits_.default_deadline;  // a client that set none
  const auto remaining = std::chrono::duration_cast<Clock::duration>(
      context->deadline() - std::chrono::system_clock::now());
  return now + std::min<Clock::duration>(remaining, limits_.max_deadline);
}

void CaptureService::FillStatus(const Caller& caller, v1::DeviceStatus* reply) {
  const DeviceSnapshot device = device_->Snapshot();
  reply->set_backend(device.capabilities.backend);
  reply->set_device(device.capabilities.device);
  reply->set_available(device.available);
  reply->set_availability_reason(device.availability_reason);
  for (Camera camera : device.capabilities.cameras) reply->add_cameras(ToProto(camera));
  reply->set_selected_camera(ToProto(device.camera));
  v1::GainRange* gain = reply->mutable_gain_range();
  gain->set_min(device.capabilities.gain.min);
  gain->set_max(device.capabilities.gain.max);
  gain->set_nominal(device.capabilities.gain.nominal);
  gain->set_unit(device.capabilities.gain.unit);
  reply->set_gain(device.gain);
  reply->set_width(static_cast<std::uint32_t>(device.capabilities.width));
  reply->set_height(static_cast<std::uint32_t>(device.capabilities.height));
  reply->set_preview_rate_hz(device.preview_rate_hz);
  FillSlideState(reply->mutable_slide());
  reply->set_software_version(software_version_);
  if (Result<store::StoreUsage> usage = store_->Usage(); usage.ok()) {
    reply->set_captures_stored(usage->captures);
    reply->set_store_free_bytes(usage->free_bytes);
  }
  reply->set_caller_role(std::string(ToString(caller.role)));
}

grpc::Status CaptureService::GetStatus(grpc::ServerContext* context, const v1::GetStatusRequest*,
                                       v1::DeviceStatus* reply) {
  Caller caller;
  if (grpc::Status s = Authorize(context, "GetStatus", &caller); !s.ok()) return s;
  FillStatus(caller, reply);
  return grpc::Status::OK;
}

grpc::Status CaptureService::SelectCamera(grpc::ServerContext* context,
                                          const v1::SelectCameraRequest* request,
                                          v1::DeviceStatus* reply) {
  Caller caller;
  if (grpc::Status s = Authorize(context, "SelectCamera", &caller); !s.ok()) return s;
  if (draining_) return Draining();
  const std::optional<Camera> camera = FromProto(request->camera());
  if (!camera)
    return Invalid("camera " + std::to_string(request->camera()) +
                   " is not a camera: use CAMERA_LEFT, CAMERA_RIGHT or CAMERA_THIRD");
  if (grpc::Status s = ToGrpc(device_->SelectCamera(*camera, Deadline(context))); !s.ok()) return s;
  spdlog::info("camera {} selected by {}", framestore::ToString(*camera), caller.Describe());
  FillStatus(caller, reply);
  return grpc::Status::OK;
}

grpc::Status CaptureService::SetGain(grpc::ServerContext* context,
                                     const v1::SetGainRequest* request, v1::DeviceStatus* reply) {
  Caller caller;
  if (grpc::Status s = Authorize(context, "SetGain", &caller); !s.ok()) return s;
  if (draining_) return Draining();
  if (grpc::Status s = ToGrpc(device_->SetGain(request->gain(), Deadline(context))); !s.ok())
    return s;
  spdlog::info("gain {} set by {}", request->gain(), caller.Describe());
  FillStatus(caller, reply);
  return grpc::Status::OK;
}

template <typename Message>
std::pair<internal::PushStream<Message>*, std::shared_ptr<internal::PushControl>>
CaptureService::OpenStream(grpc::CallbackServerContext* context, const char* what,
                           std::atomic<int>* slots, bool send_initial_metadata) {
  std::uint64_t key;
  {
    std::lock_guard lock(streams_mutex_);
    key = next_stream_++;
  }
  auto opened =
      internal::PushStream<Message>::Start({.context = context,
                                            .stalled = &stalled_writes_,
                                            .what = what,
                                            .send_initial_metadata = send_initial_metadata,
                                            .on_done = [this, key, slots] {
                                              {
                                                std::lock_guard lock(streams_mutex_);
                                                streams_.erase(key);
                                              }
                                              --*slots;
                                            }});
  {
    std::lock_guard lock(streams_mutex_);
    streams_[key] = opened.second;
  }
  // A drain that began before the stream was listed ends it too (without
  // the lock: ending may remove it at once).
  if (draining_) opened.second->End(Draining());
  return opened;
}

grpc::Status CaptureService::AdmitPreview(grpc::CallbackServerContext* context,
                                          const v1::PreviewRequest& request) {
  Caller caller;
  if (grpc::Status s = Authorize(context, "StreamPreview", &caller); !s.ok()) return s;
  if (draining_) return Draining();
  if (request.camera() != v1::CAMERA_UNSPECIFIED) {
    const std::optional<Camera> camera = FromProto(request.camera());
    if (!camera || !device_->Snapshot().capabilities.HasCamera(*camera))
      return Invalid("preview camera " + std::to_string(request.camera()) +
                     " is not one of the device's cameras");
  }
  if (request.decimation() > 250)
    return Invalid("preview decimation " + std::to_string(request.decimation()) +
                   " is above 250 (10 s between frames)");
  if (++preview_streams_ > limits_.max_preview_streams) {
    --preview_streams_;
    return {grpc::StatusCode::RESOURCE_EXHAUSTED, "bslsd already serves " +
                                                      std::to_string(limits_.max_preview_streams) +
                                                      " preview streams; close one first"};
  }
  return grpc::Status::OK;
}

grpc::ServerWriteReactor<v1::PreviewFrame>* CaptureService::StreamPreview(
    grpc::CallbackServerContext* context, const v1::PreviewRequest* request) {
  if (grpc::Status s = AdmitPreview(context, *request); !s.ok())
    return new internal::EndedStream<v1::PreviewFrame>(std::move(s));
  auto [stream, control] = OpenStream<v1::PreviewFrame>(context, "preview", &preview_streams_);
  // The stream takes the newest frame whenever its write is done: the
  // frames published meanwhile are skipped, and the next message says how
  // many. A preview of another camera than the selected one waits for it.
  std::optional<Camera> camera;
  if (request->camera() != v1::CAMERA_UNSPECIFIED) camera = FromProto(request->camera());
  const std::uint32_t every = std::max<std::uint32_t>(1, request->decimation());
  std::shared_ptr<CaptureDevice::Preview> preview =
      device_->OpenPreview(internal::WakerOf(control));
  stream->SetSource([preview, camera, every, skipped = std::uint64_t{0},
                     counter = std::uint32_t{0}]() mutable -> std::optional<v1::PreviewFrame> {
    std::uint64_t dropped = 0;
    std::shared_ptr<const framestore::GreyFrame> frame = preview->Take(&dropped);
    if (!frame) return std::nullopt;
    skipped += dropped;
    if ((camera && frame->camera != *camera) || (counter++ % every) != 0) return std::nullopt;
    v1::PreviewFrame message;
    FillFrame(*frame, true, "", message.mutable_frame());
    message.set_dropped(skipped);
    skipped = 0;
    return message;
  });
  control->Wake();
  return stream;
}

grpc::Status CaptureService::Grab(grpc::ServerContext* context, const v1::GrabRequest* request,
                                  v1::GrabResponse* reply) {
  Caller caller;
  if (grpc::Status s = Authorize(context, "Grab", &caller); !s.ok()) return s;
  if (draining_) return Draining();
  GrabSides sides;
  store::Side side;
  switch (request->side()) {
    case v1::GRAB_SIDE_LEFT:
      sides = GrabSides::kLeft;
      side = store::Side::kLeft;
      break;
    case v1::GRAB_SIDE_RIGHT:
      sides = GrabSides::kRight;
      side = store::Side::kRight;
      break;
    case v1::GRAB_SIDE_BOTH:
      sides = GrabSides::kBoth;
      side = store::Side::kBoth;
      break;
    default:
      return Invalid("grab side " + std::to_string(request->side()) +
                     " is not a side: use GRAB_SIDE_LEFT, GRAB_SIDE_RIGHT or GRAB_SIDE_BOTH");
  }
  if (grpc::Status s = CheckText(request->session_id(), "session_id"); !s.ok()) return s;
  if (grpc::Status s = CheckText(request->patient_reference(), "patient_reference"); !s.ok())
    return s;

  Result<CaptureDevice::SlideGrab> grabbed =
      device_->GrabWithSlides(sides, slides_, Deadline(context));
  if (!grabbed.ok()) {
    spdlog::error("grab {} for {} failed: {}", store::ToString(side), caller.Describe(),
                  grabbed.status().ToString());
    return ToGrpc(grabbed.status());
  }
  store::CaptureRequest capture;
  capture.session_id = request->session_id();
  capture.patient_reference = request->patient_reference();
  capture.side = side;
  capture.slide = grabbed->slide;
  capture.software_version = software_version_;
  capture.requested_by = {caller.uid, caller.name};
  capture.frames = std::move(grabbed->frames);
  Result<store::CaptureInfo> stored = store_->Put(capture);
  if (!stored.ok()) {
    spdlog::error("grab {} for {} not stored: {}", store::ToString(side), caller.Describe(),
                  stored.status().ToString());
    return ToGrpc(stored.status());
  }
  ++grabs_acknowledged_;
  spdlog::info("grab {} stored as {} for {}", store::ToString(side), stored->id.str(),
               caller.Describe());
  if (processing_) processing_->Enqueue(stored->id.str());
  FillCapture(*stored, reply->mutable_capture());
  if (request->include_frames())
    for (std::size_t i = 0; i < capture.frames.size(); ++i)
      SetPixels(capture.frames[i], reply->mutable_capture()->mutable_frames(static_cast<int>(i)));
  v1::Event event;
  v1::CaptureStored* note = event.mutable_capture_stored();
  note->set_capture_id(stored->id.str());
  note->set_side(ToProto(side));
  note->set_requested_by(caller.name);
  events_->Publish(std::move(event));
  return grpc::Status::OK;
}

grpc::Status CaptureService::ListCaptures(grpc::ServerContext* context,
                                          const v1::ListCapturesRequest* request,
                                          v1::ListCapturesResponse* reply) {
  Caller caller;
  if (grpc::Status s = Authorize(context, "ListCaptures", &caller); !s.ok()) return s;
  if (request->page_size() < 0 || request->page_size() > store::kMaxPageSize)
    return Invalid("page_size " + std::to_string(request->page_size()) + " is outside 0.." +
                   std::to_string(store::kMaxPageSize));
  store::CaptureFilter filter;
  if (!request->session_id().empty()) filter.session_id = request->session_id();
  if (!request->patient_reference().empty())
    filter.patient_reference = request->patient_reference();
  // Times the store can hold: nanoseconds since 1970 in 64 bits (until 2262).
  for (const auto& [field, has, t] :
       {std::tuple{"taken_from", request->has_taken_from(), &request->taken_from()},
        std::tuple{"taken_before", request->has_taken_before(), &request->taken_before()}})
    if (has && (t->seconds() < 0 || t->seconds() > 9'000'000'000LL || t->nanos() < 0 ||
                t->nanos() > 999'999'999))
      return Invalid(std::string(field) + ": seconds " + std::to_string(t->seconds()) + ", nanos " +
                     std::to_string(t->nanos()) + " is not a time between 1970 and 2255");
  if (request->has_taken_from()) filter.taken_from = FromProto(request->taken_from());
  if (request->has_taken_before()) filter.taken_before = FromProto(request->taken_before());
  filter.page_size = request->page_size();
  filter.page_token = request->page_token();
  Result<store::CapturePage> page = store_->List(filter);
  if (!page.ok()) return ToGrpc(page.status());
  for (const store::CaptureInfo& info : page->captures) FillCapture(info, reply->add_captures());
  reply->set_next_page_token(page->next_page_token);
  return grpc::Status::OK;
}

grpc::Status CaptureService::GetCapture(grpc::ServerContext* context,
                                        const v1::GetCaptureRequest* request,
                                        v1::CaptureInfo* reply) {
  Caller caller;
  if (grpc::Status s = Authorize(context, "GetCapture", &caller); !s.ok()) return s;
  Result<store::Capture> capture = store_->Get(request->capture_id());
  if (!capture.ok()) return ToGrpc(capture.status());
  FillCapture(capture->info, reply);
  for (std::size_t i = 0; i < capture->frames.size(); ++i)
    SetPixels(capture->frames[i], reply->mutable_frames(static_cast<int>(i)));
  return grpc::Status::OK;
}

grpc::Status CaptureService::GetCaptureResult(grpc::ServerContext* context,
                                              const v1::GetCaptureResultRequest* request,
                                              grpc::ServerWriter<v1::Artifact>* writer) {
  Caller caller;
  if (grpc::Status s = Authorize(context, "GetCaptureResult", &caller); !s.ok()) return s;
  if (request->name().size() > 64) return Invalid("name: at most 64 bytes");
  Result<std::map<std::string, std::string>> files =
      store_->ReadProcessingFiles(request->capture_id(), request->name());
  if (!files.ok()) return ToGrpc(files.status());
  for (const auto& [name, bytes] : *files) {
    const bool sent = rpc::EmitArtifact(
        name, name.ends_with(".json") ? "application/json" : "application/octet-stream", bytes,
        [this, context, writer](const v1::WorkEvent& event) {
          StalledWrites::Watch watch(stalled_writes_, context->c_call(), "result");
          return writer->Write(event.artifact());
        });
    if (!sent) return grpc::Status(grpc::StatusCode::CANCELLED, "the caller went away");
  }
  return grpc::Status::OK;
}

grpc::Status CaptureService::DeleteCapture(grpc::ServerContext* context,
                                           const v1::DeleteCaptureRequest* request,
                                           v1::DeleteCaptureResponse*) {
  Caller caller;
  if (grpc::Status s = Authorize(context, "DeleteCapture", &caller); !s.ok()) return s;
  if (draining_) return Draining();
  if (grpc::Status s = ToGrpc(store_->Delete(request->capture_id())); !s.ok()) return s;
  spdlog::info("capture {} deleted by {}", request->capture_id(), caller.Describe());
  v1::Event event;
  event.mutable_capture_deleted()->set_capture_id(request->capture_id());
  event.mutable_capture_deleted()->set_deleted_by(caller.name);
  events_->Publish(std::move(event));
  return grpc::Status::OK;
}

void CaptureService::FillSlideState(v1::SlideState* reply) const {
  if (slides_ == nullptr) {
    reply->set_last_error("no slide controller is configured");
    return;
  }
  const slides::SlideState state = slides_->State();
  reply->set_slide(state.slide);
  reply->set_in_place(state.in_place);
  reply->set_moving(state.moving);
  reply->set_lamp_on(state.lamp_on);
  reply->set_focus_position(state.focus_position);
  reply->set_last_error(state.last_error);
}

namespace {

grpc::Status NoSlides() {
  return {grpc::StatusCode::UNAVAILABLE,
          "bslsd has no slide controller (slides.backend is none in its configuration)"};
}

}  // namespace

grpc::Status CaptureService::GetSlideState(grpc::ServerContext* context,
                                           const v1::GetSlideStateRequest*, v1::SlideState* reply) {
  Caller caller;
  if (grpc::Status s = Authorize(context, "GetSlideState", &caller); !s.ok()) return s;
  FillSlideState(reply);
  return grpc::Status::OK;
}

grpc::Status CaptureService::SetSlide(grpc::ServerContext* context,
                                      const v1::SetSlideRequest* request, v1::SlideState* reply) {
  Caller caller;
  if (grpc::Status s = Authorize(context, "SetSlide", &caller); !s.ok()) return s;
  if (draining_) return Draining();
  if (slides_ == nullptr) return NoSlides();
  if (request->slide() < 1 || request->slide() > 3)
    return Invalid("slide " + std::to_string(request->slide()) +
                   " does not exist: 1 reference, 2 left pattern, 3 right pattern");
  spdlog::info("slide {} requested by {}", request->slide(), caller.Describe());
  if (grpc::Status s = ToGrpc(slides_->ChangeTo(request->slide(), Deadline(context))); !s.ok()) {
    spdlog::error("slide {} for {} failed: {}", request->slide(), caller.Describe(),
                  s.error_message());
    return s;
  }
  FillSlideState(reply);
  return grpc::Status::OK;
}

grpc::Status CaptureService::SetFocus(grpc::ServerContext* context,
                                      const v1::SetFocusRequest* request, v1::SlideState* reply) {
  Caller caller;
  if (grpc::Status s = Authorize(context, "SetFocus", &caller); !s.ok()) return s;
  if (draining_) return Draining();
  if (slides_ == nullptr) return NoSlides();
  if (request->steps() < -1000 || request->steps() > 1000)
    return Invalid("focus steps " + std::to_string(request->steps()) + " is outside -1000..1000");
  spdlog::info("focus {:+d} steps by {}", request->steps(), caller.Describe());
  if (grpc::Status s = ToGrpc(slides_->Focus(request->steps(), Deadline(context))); !s.ok())
    return s;
  FillSlideState(reply);
  return grpc::Status::OK;
}

grpc::Status CaptureService::SetLamp(grpc::ServerContext* context,
                                     const v1::SetLampRequest* request, v1::SlideState* reply) {
  Caller caller;
  if (grpc::Status s = Authorize(context, "SetLamp", &caller); !s.ok()) return s;
  if (draining_) return Draining();
  if (slides_ == nullptr) return NoSlides();
  spdlog::info("lamp {} by {}", request->on() ? "on" : "off", caller.Describe());
  if (grpc::Status s = ToGrpc(slides_->SetLamp(request->on())); !s.ok()) return s;
  FillSlideState(reply);
  return grpc::Status::OK;
}

grpc::ServerWriteReactor<v1::Event>* CaptureService::WatchEvents(
    grpc::CallbackServerContext* context, const v1::WatchEventsRequest*) {
  Caller caller;
  if (grpc::Status s = Authorize(context, "WatchEvents", &caller); !s.ok())
    return new internal::EndedStream<v1::Event>(std::move(s));
  if (draining_) return new internal::EndedStream<v1::Event>(Draining());
  if (++event_streams_ > limits_.max_event_streams) {
    --event_streams_;
    return new internal::EndedStream<v1::Event>(
        {grpc::StatusCode::RESOURCE_EXHAUSTED, "bslsd already serves " +
                                                   std::to_string(limits_.max_event_streams) +
                                                   " event streams; close one first"});
  }
  auto [stream, control] = OpenStream<v1::Event>(context, "events", &event_streams_, true);
  std::shared_ptr<EventHub::Watcher> watcher = events_->Watch(internal::WakerOf(control));
  // A watcher that read too slowly lost its oldest events: it is told how
  // many before the next one.
  stream->SetSource(
      [watcher, held = std::optional<v1::Event>()]() mutable -> std::optional<v1::Event> {
        if (held) return std::exchange(held, std::nullopt);
        std::uint64_t dropped = 0;
        std::optional<v1::Event> event = watcher->Take(&dropped);
        if (!event || dropped == 0) return event;
        v1::Event lost;
        *lost.mutable_time() = event->time();
        lost.mutable_error()->set_message(std::to_string(dropped) +
                                          " events were dropped: this watcher read too slowly");
        held = std::move(event);
        return lost;
      });
  control->Wake();
  return stream;
}

void CaptureService::BeginDrain() {
  draining_ = true;
  std::vector<std::shared_ptr<internal::PushControl>> open;
  {
    std::lock_guard lock(streams_mutex_);
    for (const auto& [key, control] : streams_) open.push_back(control);
  }
  for (const auto& control : open) control->End(Draining());
}

}  // namespace bsls::service
