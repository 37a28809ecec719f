#include "bsls/service/processing_queue.h"

#include <google/protobuf/util/json_util.h>
#include <spdlog/spdlog.h>

#include <nlohmann/json.hpp>
#include <set>

#include "bsls/common/sha256.h"
#include "bsls/service/contract_messages.h"

namespace bsls::service {
namespace {

using Clock = std::chrono::steady_clock;

// Statuses that say the input itself cannot be processed: trying again
// would give the same answer.
bool IsPermanent(const grpc::Status& status) {
  switch (status.error_code()) {
    case grpc::StatusCode::INVALID_ARGUMENT:
    case grpc::StatusCode::FAILED_PRECONDITION:
    case grpc::StatusCode::NOT_FOUND:
    case grpc::StatusCode::OUT_OF_RANGE:
      return true;
    default:
      return false;
  }
}

std::string Describe(const grpc::Status& status) {
  return "processing service: status " + std::to_string(status.error_code()) + ": " +
         status.error_message();
}

nlohmann::json JsonOf(const google::protobuf::Message& message) {
  google::protobuf::util::JsonPrintOptions options;
  options.preserve_proto_field_names = true;
  std::string text;
  (void)google::protobuf::util::MessageToJsonString(message, &text, options);
  return nlohmann::json::parse(text, nullptr, false);
}

// The cameras of a capture that have a side, each with its frame.
std::map<framestore::Camera, const framestore::GreyFrame*> FramesBySide(
    const store::Capture& capture) {
  std::map<framestore::Camera, const framestore::GreyFrame*> frames;
  for (const framestore::GreyFrame& frame : capture.frames)
    if (frame.camera == framestore::Camera::kLeft || frame.camera == framestore::Camera::kRight)
      frames[frame.camera] = &frame;
  return frames;
}

}  // namespace

ProcessingQueue::ProcessingQueue(store::CaptureStore* store, EventHub* events,
                                 ProcessingQueueOptions options)
    : store_(store), events_(events), options_(std::move(options)) {}

ProcessingQueue::~ProcessingQueue() { Stop(); }

void ProcessingQueue::Start() {
  if (!enabled() || worker_.joinable()) return;
  client_ = std::make_unique<processing::ProcessingClient>(
      processing::OpenProcessingChannel(options_.client), options_.client);
  worker_ = std::thread([this] { Run(); });
}

void ProcessingQueue::Enqueue(const std::string& capture_id) {
  if (!enabled()) return;
  {
    std::lock_guard lock(mutex_);
    queued_.push_back(capture_id);
  }
  wake_.notify_all();
}

void ProcessingQueue::Stop() {
  {
    std::lock_guard lock(mutex_);
    if (stopping_) return;
    stopping_ = true;
  }
  wake_.notify_all();
  if (client_) client_->CancelAll();
  if (worker_.joinable()) worker_.join();
}

void ProcessingQueue::Run() {
  std::deque<std::string> order;  // oldest first
  std::set<std::string> known;
  auto backoff = options_.retry_initial;
  Clock::time_point retry_at{};
  std::unique_lock lock(mutex_);
  while (!stopping_) {
    if (rescan_) {
      rescan_ = false;
      lock.unlock();
      auto pending = store_->Unprocessed();
      lock.lock();
      if (!pending.ok()) {
        spdlog::error("processing queue: {}", pending.status().message());
        rescan_ = true;
        wake_.wait_for(lock, options_.retry_max);
        continue;
      }
      for (const store::CaptureId& id : *pending)
        if (known.insert(id.str()).second) order.push_back(id.str());
      if (!order.empty())
        spdlog::info("processing queue: {} captures waiting for processing", order.size());
    }
    for (; !queued_.empty(); queued_.pop_front())
      if (known.insert(queued_.front()).second) order.push_back(queued_.front());
    if (order.empty()) {
      wake_.wait(lock);
      continue;
    }
    if (Clock::now() < retry_at) {
      wake_.wait_until(lock, retry_at);
      continue;
    }
    const std::string id = order.front();
    lock.unlock();
    std::string error;
    const Outcome outcome = ProcessOne(id, &error);
    lock.lock();
    if (outcome == Outcome::kRetry) {
      if (stopping_) break;  // the call was cancelled by Stop: still pending
      spdlog::warn("processing of capture {} will be tried again in {} ms: {}", id, backoff.count(),
                   error);
      lock.unlock();
      if (auto noted = store_->NoteProcessingAttempt(id, error); !noted.ok())
        spdlog::error("processing queue: {}", noted.message());
      lock.lock();
      retry_at = Clock::now() + backoff;
      backoff = std::min(backoff * 2, options_.retry_max);
      continue;
    }
    order.pop_front();
    known.erase(id);
    backoff = options_.retry_initial;
    retry_at = {};
    if (outcome == Outcome::kGone) continue;
    ++finished_;
    if (outcome == Outcome::kFailed)
      spdlog::error("processing of capture {} failed: {}", id, error);
    lock.unlock();
    Publish(id);
    lock.lock();
  }
}

ProcessingQueue::Outcome ProcessingQueue::ProcessOne(const std::string& id, std::string* error) {
  Result<store::Capture> capture = store_->Get(id);
  if (!capture.ok()) {
    *error = capture.status().message();
    if (capture.status().code() == ErrorCode::kNotFound) return Outcome::kGone;
    if (capture.status().code() == ErrorCode::kDataLoss) {
      *error = "the capture is damaged: " + *error;
      if (auto s = store_->PutProcessingFailure(id, *error); !s.ok()) *error += "; " + s.message();
      return Outcome::kFailed;
    }
    return Outcome::kRetry;
  }
  Processed processed;
  processed.provenance.daemon_software_version = options_.daemon_version;
  const SideFrames frames = FramesBySide(*capture);
  const bool both = frames.size() == 2 && !options_.left_calibration.empty() &&
                    !options_.right_calibration.empty();
  if (grpc::Status s =
          both ? ReconstructBoth(id, frames, &processed) : ProcessEachSide(id, frames, &processed);
      !s.ok())
    return Failed(id, s, error);
  if (auto stored = store_->PutProcessingResult(id, processed.files, processed.provenance);
      !stored.ok()) {
    *error = stored.message();
    return stored.code() == ErrorCode::kNotFound ? Outcome::kGone : Outcome::kRetry;
  }
  return Outcome::kDone;
}

grpc::Status ProcessingQueue::ReconstructBoth(const std::string& id, const SideFrames& frames,
                                              Processed* out) {
  v1::ReconstructSessionRequest request;
  FillFrame(*frames.at(framestore::Camera::kLeft), true, "", request.mutable_left());
  FillFrame(*frames.at(framestore::Camera::kRight), true, "", request.mutable_right());
  *request.mutable_left_calibration() =
      processing::ProcessingClient::Inline(options_.left_calibration);
  *request.mutable_right_calibration() =
      processing::ProcessingClient::Inline(options_.right_calibration);
  request.set_want_side_surfaces(true);
  request.set_want_junctions(true);
  request.set_request_tag(id);
  const processing::WorkOutcome result = client_->ReconstructSession(request);
  if (!result.status.ok()) return result.status;
  out->files.insert(result.files.begin(), result.files.end());
  out->provenance.call = "ReconstructSession";
  out->provenance.results.push_back(JsonOf(result.result));
  out->provenance.replica = result.result.replica();
  out->provenance.processing_software_version = result.result.software_version();
  KeepCalibration(framestore::Camera::kLeft, out);
  KeepCalibration(framestore::Camera::kRight, out);
  return grpc::Status::OK;
}

grpc::Status ProcessingQueue::ProcessEachSide(const std::string& id, const SideFrames& frames,
                                              Processed* out) {
  out->provenance.call = "ProcessFrame";
  for (const auto& [camera, frame] : frames) {
    v1::ProcessFrameRequest request;
    FillFrame(*frame, true, "", request.mutable_frame());
    request.set_side(camera == framestore::Camera::kLeft ? v1::SIDE_LEFT : v1::SIDE_RIGHT);
    const std::string& yaml = CalibrationOf(camera);
    if (!yaml.empty()) {
      *request.mutable_calibration() = processing::ProcessingClient::Inline(yaml);
      request.set_want_surface(true);
    }
    request.set_want_overlay(true);
    request.set_request_tag(id);
    const processing::WorkOutcome result = client_->ProcessFrame(request);
    if (!result.status.ok()) return result.status;
    // Both sides without both calibrations: each side's files by its name.
    const std::string prefix =
        frames.size() > 1 ? std::string(framestore::ToString(camera)) + "." : "";
    for (const auto& [name, bytes] : result.files) out->files[prefix + name] = bytes;
    out->provenance.results.push_back(JsonOf(result.result));
    out->provenance.replica = result.result.replica();
    out->provenance.processing_software_version = result.result.software_version();
    KeepCalibration(camera, out);
  }
  return grpc::Status::OK;
}

void ProcessingQueue::KeepCalibration(framestore::Camera camera, Processed* out) const {
  const std::string& yaml = CalibrationOf(camera);
  if (yaml.empty()) return;
  out->provenance.calibrations[framestore::ToString(camera)] =
      "sha256:" + Sha256Hex(yaml);  // the service's id
  out->files[std::string("calibration-") + framestore::ToString(camera) + ".yaml"] = yaml;
}

ProcessingQueue::Outcome ProcessingQueue::Failed(const std::string& id, const grpc::Status& status,
                                                 std::string* error) {
  *error = Describe(status);
  if (!IsPermanent(status)) return Outcome::kRetry;
  if (auto s = store_->PutProcessingFailure(id, *error); !s.ok()) {
    *error += "; " + s.message();
    return Outcome::kRetry;
  }
  return Outcome::kFailed;
}

void ProcessingQueue::Publish(const std::string& id) {
  auto record = store_->Processing(id);
  if (!record.ok() || !*record) return;
  v1::Event event;
  event.mutable_processing_finished()->set_capture_id(id);
  FillProcessingStatus(**record, true, event.mutable_processing_finished()->mutable_status());
  events_->Publish(std::move(event));
}

void FillProcessingStatus(const std::optional<store::ProcessingRecord>& record, bool enabled,
                          v1::ProcessingStatus* out) {
  if (!record) {
    out->set_state(enabled ? v1::ProcessingStatus::STATE_PENDING
                           : v1::ProcessingStatus::STATE_DISABLED);
    return;
  }
  switch (record->state) {
    case store::ProcessingState::kDone:
      out->set_state(v1::ProcessingStatus::STATE_DONE);
      break;
    case store::ProcessingState::kFailed:
      out->set_state(v1::ProcessingStatus::STATE_FAILED);
      break;
    default:
      out->set_state(enabled ? v1::ProcessingStatus::STATE_PENDING
                             : v1::ProcessingStatus::STATE_DISABLED);
  }
  out->set_attempts(static_cast<std::uint32_t>(record->attempts));
  out->set_last_error(record->last_error);
  out->set_replica(record->replica);
  out->set_software_version(record->software_version);
  if (const auto it = record->files.find("record.json"); it != record->files.end())
    out->set_record_sha256(it->second);
  for (const auto& [name, sha256] : record->files) out->add_files(name);
  const auto since_epoch = record->updated.time_since_epoch();
  const auto seconds = std::chrono::duration_cast<std::chrono::seconds>(since_epoch);
  if (record->state != store::ProcessingState::kPending) {
    out->mutable_finished()->set_seconds(seconds.count());
    out->mutable_finished()->set_nanos(static_cast<int>(
        std::chrono::duration_cast<std::chrono::nanoseconds>(since_epoch - seconds).count()));
  }
}

}  // namespace bsls::service
