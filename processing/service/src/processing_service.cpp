#include "bsls/processing/processing_service.h"

#include <google/protobuf/descriptor.h>
#include <grpcpp/support/method_handler.h>
#include <spdlog/spdlog.h>
#include <stdlib.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <chrono>
#include <fstream>
#include <future>
#include <map>
#include <opencv2/imgcodecs.hpp>
#include <optional>

#include "bsls/calibration/calibration_error.h"
#include "bsls/calibration/calibration_file.h"
#include "bsls/calibration/calibration_report.h"
#include "bsls/calibration/manifest.h"
#include "bsls/common/errors.h"
#include "bsls/common/sha256.h"
#include "bsls/config/bounded_yaml.h"
#include "bsls/contract/frame_message.h"
#include "bsls/contract/processing_messages.h"
#include "bsls/decoder/decode_output.h"
#include "bsls/io/surface_file.h"
#include "bsls/measurement/measurement_error.h"
#include "bsls/rpc/artifacts.h"
#include "bsls/rpc/server_limits.h"
#include "bsls/session/session.h"
#include "work_stream.h"

namespace bsls::processing {
namespace {

using grpc::Status;
using grpc::StatusCode;
namespace fs = std::filesystem;

constexpr std::size_t kMaxTagBytes = 256;
constexpr std::size_t kMaxPathBytes = 256;
constexpr std::size_t kMaxChunkBytes = 4u << 20;

// A request that cannot be served, with the status that says why.
struct Refusal {
  Status status;
};

[[noreturn]] void Refuse(StatusCode code, const std::string& message) {
  throw Refusal{Status(code, message)};
}

void CheckTag(const std::string& tag) {
  if (tag.size() > kMaxTagBytes)
    Refuse(StatusCode::INVALID_ARGUMENT,
           "request_tag: " + std::to_string(tag.size()) + " bytes, at most 256");
}

// The frame `name` of a request; contract::MessageError when malformed,
// refused (INVALID_ARGUMENT) above `max_pixels`.
cv::Mat FrameOf(const v1::Frame& frame, const std::string& name, std::int64_t max_pixels) {
  const cv::Mat grey = contract::FrameView(frame, name);
  if (static_cast<std::int64_t>(grey.total()) > max_pixels)
    Refuse(StatusCode::INVALID_ARGUMENT,
           name + ": " + std::to_string(grey.cols) + " x " + std::to_string(grey.rows) + " = " +
               std::to_string(grey.total()) + " pixels is above this service's budget of " +
               std::to_string(max_pixels) + " (max_frame_pixels)");
  return grey;
}

void FillInfo(const CachedCalibration& c, v1::CalibrationInfo* info) {
  info->set_id(c.id);
  info->set_side(contract::ToProto(c.calibration.side));
  info->set_width(static_cast<std::uint32_t>(c.calibration.width));
  info->set_height(static_cast<std::uint32_t>(c.calibration.height));
  info->set_software_version(c.software_version);
  info->set_has_projector_matrix(c.calibration.projector_matrix.has_value());
}

StatusCode CodeOf(calibration::CalibrationErrorReason reason) {
  switch (reason) {
    case calibration::CalibrationErrorReason::kInvalidInput:
    case calibration::CalibrationErrorReason::kUnreadableInput:
      return StatusCode::INVALID_ARGUMENT;
    case calibration::CalibrationErrorReason::kInvalidParams:
      return StatusCode::INTERNAL;
    case calibration::CalibrationErrorReason::kCancelled:
      return StatusCode::CANCELLED;
    default:
      return StatusCode::FAILED_PRECONDITION;
  }
}

std::string DefaultReplicaName() {
  char host[256] = {};
  ::gethostname(host, sizeof host - 1);
  return std::string(host) + ":" + std::to_string(::getpid());
}

// A private folder for one upload, removed with everything in it.
class ScratchFolder {
 public:
  explicit ScratchFolder(const fs::path& parent) {
    std::string pattern = (parent / "bsls-calibrate-XXXXXX").string();
    if (::mkdtemp(pattern.data()) == nullptr)
      Refuse(StatusCode::INTERNAL, "cannot create a scratch folder in " + parent.string());
    path_ = pattern;
  }
  ~ScratchFolder() {
    std::error_code ec;
    fs::remove_all(path_, ec);
  }
  const fs::path& path() const { return path_; }

 private:
  fs::path path_;
};

// A relative path of an upload that stays inside its folder; refused otherwise.
fs::path UploadPath(const std::string& path) {
  if (path.empty() || path.size() > kMaxPathBytes || path.find('\0') != std::string::npos)
    Refuse(StatusCode::INVALID_ARGUMENT,
           "file.path \"" + path.substr(0, 64) + "\": must be 1..256 bytes");
  const fs::path p(path);
  if (p.is_absolute())
    Refuse(StatusCode::INVALID_ARGUMENT, "file.path \"" + path + "\": must be relative");
  for (const fs::path& part : p)
    if (part == ".." || part == "." || part.empty())
      Refuse(StatusCode::INVALID_ARGUMENT,
             "file.path \"" + path + "\": must not contain \".\" or \"..\"");
  if (p == "manifest.yaml")
    Refuse(StatusCode::INVALID_ARGUMENT, "file.path \"manifest.yaml\": is the manifest's own name");
  return p;
}

// SHA-256 of the frame's packed pixels (width * height bytes, as the
// capture store hashes them).
std::string PackedSha256(const cv::Mat& grey) {
  const cv::Mat packed = grey.isContinuous() ? grey : grey.clone();
  return Sha256Hex(std::string_view(reinterpret_cast<const char*>(packed.data), packed.total()));
}

// Refuses a manifest whose `image:` entries (at any depth) are not relative
// paths inside its folder; a manifest that is not YAML is left to LoadManifest.
void ConfineManifestImages(const std::string& yaml) {
  YAML::Node root;
  try {
    root = LoadBoundedYaml(yaml);
  } catch (const YAML::Exception&) {
    return;
  }
  std::function<void(const YAML::Node&)> visit = [&](const YAML::Node& node) {
    if (node.IsMap()) {
      for (const auto& item : node) {
        if (item.first.IsScalar() && item.first.Scalar() == "image" && item.second.IsScalar()) {
          const fs::path image(item.second.Scalar());
          bool inside = !image.empty() && image.is_relative();
          for (const fs::path& part : image) inside = inside && part != "..";
          if (!inside)
            Refuse(StatusCode::INVALID_ARGUMENT,
                   "manifest: image " + item.second.Scalar().substr(0, 256) +
                       " is not one of the uploaded files (paths must stay inside the "
                       "manifest's folder)");
        }
        visit(item.second);
      }
    } else if (node.IsSequence()) {
      for (const auto& item : node) visit(item);
    }
  };
  visit(root);
}

// OK when the first message of a Calibrate upload is a manifest within the
// limits; else the status that refuses it.
Status CheckManifestMessage(const v1::CalibrateRequest& first, std::size_t max_manifest_bytes) {
  if (first.part_case() != v1::CalibrateRequest::kManifest)
    return Status(StatusCode::INVALID_ARGUMENT,
                  "Calibrate: the first message must be the manifest");
  if (first.manifest().yaml().size() > max_manifest_bytes)
    return Status(StatusCode::INVALID_ARGUMENT,
                  "manifest.yaml: " + std::to_string(first.manifest().yaml().size()) +
                      " bytes, at most " + std::to_string(max_manifest_bytes));
  if (first.manifest().request_tag().size() > kMaxTagBytes)
    return Status(StatusCode::INVALID_ARGUMENT, "manifest.request_tag: at most 256 bytes");
  return Status::OK;
}

// The Calibrate stream with its messages parsed here rather than by gRPC,
// which ends the reads at a message that does not parse as it does at the
// client's half-close, so that the handler cannot tell them apart.
class UploadStream {
 public:
  explicit UploadStream(grpc::ServerReaderWriter<grpc::ByteBuffer, grpc::ByteBuffer>* raw)
      : raw_(raw) {}

  // The upload's next message into *part; false at the upload's end; refuses
  // (INVALID_ARGUMENT naming its number and size) bytes that are not a
  // CalibrateRequest.
  bool Read(v1::CalibrateRequest* part) {
    grpc::ByteBuffer bytes;
    if (!raw_->Read(&bytes)) return false;
    ++messages_;
    const std::size_t size = bytes.Length();
    if (!grpc::SerializationTraits<v1::CalibrateRequest>::Deserialize(&bytes, part).ok())
      Refuse(StatusCode::INVALID_ARGUMENT,
             "Calibrate: message " + std::to_string(messages_) + " of the upload (" +
                 std::to_string(size) + " bytes) is not a " +
                 v1::CalibrateRequest::descriptor()->full_name() + " message");
    return true;
  }

  // Sends `event` to the caller; false when the call is over.
  bool Write(const v1::WorkEvent& event) {
    grpc::ByteBuffer bytes;
    bool own = false;
    if (!grpc::SerializationTraits<v1::WorkEvent>::Serialize(event, &bytes, &own).ok())
      return false;
    return raw_->Write(bytes);
  }

 private:
  grpc::ServerReaderWriter<grpc::ByteBuffer, grpc::ByteBuffer>* raw_;
  int messages_ = 0;  // read so far
};

// The upload: every file in order, chunk by chunk, within the limits,
// written under `folder`; refused (INVALID_ARGUMENT naming the file, INTERNAL
// when the scratch folder fails) otherwise.
void ReceiveUploadFiles(UploadStream* stream, const fs::path& folder,
                        const ProcessingServiceOptions& options,
                        const session::WorkObserver& observer) {
  std::map<fs::path, std::uint64_t> sizes;  // bytes received so far, by file
  std::map<fs::path, bool> complete;
  std::uint64_t total = 0;
  std::optional<fs::path> open_path;
  std::ofstream out;
  v1::CalibrateRequest part;
  while (stream->Read(&part)) {
    observer.CheckCancelled("the upload's end");
    if (part.part_case() == v1::CalibrateRequest::kManifest)
      Refuse(StatusCode::INVALID_ARGUMENT, "Calibrate: a second manifest in the upload");
    if (part.part_case() != v1::CalibrateRequest::kFile)
      Refuse(StatusCode::INVALID_ARGUMENT,
             "Calibrate: a message of the upload with neither a manifest nor a file chunk");
    const v1::FileChunk& chunk = part.file();
    const fs::path path = UploadPath(chunk.path());
    const std::string name = "file " + chunk.path();
    if (chunk.data().size() > kMaxChunkBytes)
      Refuse(StatusCode::INVALID_ARGUMENT, name + ": a chunk above 4 MiB");
    if (complete.count(path)) Refuse(StatusCode::INVALID_ARGUMENT, name + ": sent twice");
    if (open_path != path) {
      if (open_path)
        Refuse(StatusCode::INVALID_ARGUMENT,
               name + ": begun before file " + open_path->string() + " was complete");
      if (static_cast<int>(complete.size()) >= options.max_upload_files)
        Refuse(StatusCode::INVALID_ARGUMENT,
               name + ": more than " + std::to_string(options.max_upload_files) + " files");
      // A path whose folder is an uploaded file, or a file named like an
      // uploaded folder, cannot be made: the upload contradicts itself.
      std::error_code ec;
      fs::create_directories(folder / path.parent_path(), ec);
      if (!ec) out.open(folder / path, std::ios::binary | std::ios::trunc);
      if (ec || !out)
        Refuse(StatusCode::INVALID_ARGUMENT,
               name + ": clashes with another uploaded path (a file and a folder of one name)");
      open_path = path;
    }
    if (chunk.offset() != sizes[path])
      Refuse(StatusCode::INVALID_ARGUMENT, name + ": a chunk at offset " +
                                               std::to_string(chunk.offset()) + " after " +
                                               std::to_string(sizes[path]) + " bytes");
    total += chunk.data().size();
    if (total > options.max_upload_bytes)
      Refuse(StatusCode::INVALID_ARGUMENT, "Calibrate: the upload exceeds " +
                                               std::to_string(options.max_upload_bytes) + " bytes");
    out.write(chunk.data().data(), static_cast<std::streamsize>(chunk.data().size()));
    sizes[path] += chunk.data().size();
    if (chunk.last()) {
      out.close();
      if (!out) Refuse(StatusCode::INTERNAL, name + ": cannot be written to the scratch folder");
      complete[path] = true;
      open_path.reset();
    }
  }
  if (open_path)
    Refuse(StatusCode::INVALID_ARGUMENT,
           "file " + open_path->string() + ": the upload ended before its last chunk");
}

// `text` without any occurrence of `prefix` (the scratch folder's path):
// paths in errors are the client's, not the scratch folder's.
std::string WithoutPrefix(std::string text, const std::string& prefix) {
  for (size_t at; (at = text.find(prefix)) != std::string::npos;) text.erase(at, prefix.size());
  return text;
}

// The manifest uploaded into `folder` (its text `yaml`), read; refused
// (INVALID_ARGUMENT) when it is malformed or names a file outside the upload.
calibration::Manifest LoadUploadedManifest(const fs::path& folder, const std::string& yaml,
                                           const std::string& prefix) {
  // Image paths are checked before the manifest is read: reading it asks
  // whether each image exists, which must not be asked of the server's disk.
  ConfineManifestImages(yaml);
  calibration::Manifest manifest;
  try {
    manifest = calibration::LoadManifest(folder / "manifest.yaml");
  } catch (const calibration::ManifestError& e) {
    Refuse(StatusCode::INVALID_ARGUMENT, WithoutPrefix(e.what(), prefix));
  }
  // The manifest may only name files of the upload.
  const fs::path root = fs::weakly_canonical(folder);
  for (const auto* views :
       {&manifest.camera_views, &manifest.screen_views, &manifest.reference_views})
    for (const calibration::ManifestView& view : *views) {
      const fs::path image = fs::weakly_canonical(view.image);
      const auto [end, _] = std::mismatch(root.begin(), root.end(), image.begin(), image.end());
      if (end != root.end())
        Refuse(StatusCode::INVALID_ARGUMENT,
               "manifest: image " + WithoutPrefix(view.image.string(), prefix) +
                   " is not one of the uploaded files (paths must stay inside the manifest's "
                   "folder)");
    }
  return manifest;
}

// Image paths as the client named them (relative to the manifest), so an
// upload gives the same file, and the same id, on every replica.
void UseClientPaths(calibration::SideCalibration& result, const fs::path& folder,
                    const std::string& prefix) {
  for (auto& v : result.camera_views) v.image = fs::relative(v.image, folder);
  for (auto& v : result.screen_views) v.image = fs::relative(v.image, folder);
  for (auto& v : result.reference_views) v.image = fs::relative(v.image, folder);
  for (auto& v : result.dropped_views) {
    v.image = fs::relative(v.image, folder);
    v.reason = WithoutPrefix(v.reason, prefix);
  }
}

}  // namespace

std::shared_ptr<const CachedCalibration> ProcessingService::ResolveCalibration(
    const v1::CalibrationSource& source, const std::string& field) {
  switch (source.source_case()) {
    case v1::CalibrationSource::kId: {
      auto found = calibrations_.Find(source.id());
      if (!found)
        Refuse(StatusCode::NOT_FOUND,
               field + ".id " + source.id().substr(0, 80) + ": replica " + options_.replica +
                   " does not hold this calibration; send the file (inline or PutCalibration)");
      return found;
    }
    case v1::CalibrationSource::kYaml:
      try {
        return calibrations_.Put(source.yaml(), field + ".yaml");
      } catch (const calibration::CalibrationFileError& e) {
        Refuse(StatusCode::INVALID_ARGUMENT, e.what());
      }
    default:
      Refuse(StatusCode::INVALID_ARGUMENT, field + ": give an id or the file");
  }
}

// What a work call's checks need: its name, whether its caller gave up
// (cancelled, deadline, drain) and the status that says which.
struct ProcessingService::CallState {
  std::string name;
  std::function<bool()> gave_up;
  std::function<Status()> stopped;
};

namespace {

// A progress event: `stage` begins with `fraction` of the work done.
v1::WorkEvent Progress(std::string_view stage, double fraction) {
  v1::WorkEvent event;
  event.mutable_progress()->set_stage(std::string(stage));
  event.mutable_progress()->set_fraction(fraction);
  return event;
}

}  // namespace

// What a work call's body gets: where to send events and how to observe.
struct ProcessingService::Work {
  // The work of `call`, its events sent through `send`: the stages ask
  // whether the caller gave up and report progress as events.
  Work(Emit send, const CallState& call) : emit(std::move(send)) {
    observer.cancelled = call.gave_up;
    observer.progress = [this](std::string_view stage, double fraction) {
      emit(Progress(stage, fraction));
    };
  }
  Work(const Work&) = delete;  // the observer refers to this one
  Work& operator=(const Work&) = delete;

  Emit emit;  // sends an event; false when the caller went away
  session::WorkObserver observer;
  v1::Result result;
  std::chrono::steady_clock::time_point start = std::chrono::steady_clock::now();

  // Sends an output file; false when the caller went away.
  void Artifact(const std::string& name, const std::string& media_type, std::string_view bytes) {
    if (!rpc::EmitArtifact(name, media_type, bytes, emit))
      throw session::Cancelled("the caller went away while " + name + " was sent");
  }
  // Sends `image` as a PNG file.
  void Png(const std::string& name, const cv::Mat& image) {
    std::vector<unsigned char> png;
    if (!cv::imencode(".png", image, png)) throw std::runtime_error(name + ": PNG encoding failed");
    Artifact(name, "image/png",
             std::string_view(reinterpret_cast<const char*>(png.data()), png.size()));
  }
  void Time(const std::string& stage, double ms) {
    v1::StageTime* t = result.add_times();
    t->set_stage(stage);
    t->set_ms(ms);
  }
};

ProcessingService::ProcessingService(ProcessingServiceOptions options)
    : options_(std::move(options)),
      calibrations_(options_.calibration_cache_entries),
      pool_(options_.workers, options_.queue) {
  if (options_.replica.empty()) options_.replica = DefaultReplicaName();
  // Calibrate's messages are parsed by CalibrateUpload, not by gRPC. The
  // generated service adds its methods in the .proto's order.
  const int calibrate = google::protobuf::DescriptorPool::generated_pool()
                            ->FindServiceByName(v1::Processing::service_full_name())
                            ->FindMethodByName("Calibrate")
                            ->index();
  MarkMethodStreamed(calibrate,
                     new grpc::internal::BidiStreamingHandler<ProcessingService, grpc::ByteBuffer,
                                                              grpc::ByteBuffer>(
                         [](ProcessingService* service, grpc::ServerContext* context,
                            grpc::ServerReaderWriter<grpc::ByteBuffer, grpc::ByteBuffer>* stream) {
                           return service->CalibrateUpload(context, stream);
                         },
                         this));
}

void ProcessingService::BeginDrain() { draining_ = true; }

namespace {

// The call state of `context`'s call; `cancelled` adds what the transport
// knows beyond the context (a failed write).
template <typename Context>
std::function<bool()> GaveUp(Context* context, const std::atomic<bool>& draining,
                             std::function<bool()> cancelled = {}) {
  const auto deadline = context->deadline();
  return [context, &draining, deadline, cancelled = std::move(cancelled)] {
    return context->IsCancelled() || draining || std::chrono::system_clock::now() > deadline ||
           (cancelled && cancelled());
  };
}

template <typename Context>
std::function<Status()> Stopped(Context* context, const std::atomic<bool>& draining,
                                const std::string& call) {
  const auto deadline = context->deadline();
  return [context, &draining, deadline, call] {
    if (std::chrono::system_clock::now() > deadline)
      return Status(StatusCode::DEADLINE_EXCEEDED, call + ": the deadline passed; work stopped");
    if (draining && !context->IsCancelled())
      return Status(StatusCode::UNAVAILABLE, call + ": the service is shutting down; work stopped");
    return Status(StatusCode::CANCELLED, call + ": cancelled; work stopped");
  };
}

}  // namespace

Status ProcessingService::Admit(std::optional<WorkPool::Place>* place) {
  if (draining_) return Status(StatusCode::UNAVAILABLE, "the service is shutting down");
  if (std::optional<WorkPool::Place> admitted = pool_.TryAdmit()) {
    place->emplace(std::move(*admitted));
    return Status::OK;
  }
  const WorkPoolStats s = pool_.Stats();
  return Status(StatusCode::RESOURCE_EXHAUSTED,
                "replica " + options_.replica + " is full: " + std::to_string(s.workers) +
                    " workers and " + std::to_string(s.queue) +
                    " queue places taken; retry later or on another replica");
}

Status ProcessingService::Guarded(const CallState& call, const std::function<void()>& body) {
  try {
    body();
  } catch (const Refusal& r) {
    return r.status;
  } catch (const session::Cancelled&) {
    return call.stopped();
  } catch (const session::SessionError& e) {
    return Status(e.reason() == session::SessionErrorReason::kInvalidInput
                      ? StatusCode::INVALID_ARGUMENT
                      : StatusCode::FAILED_PRECONDITION,
                  e.what());
  } catch (const calibration::CalibrationError& e) {
    if (e.reason() == calibration::CalibrationErrorReason::kCancelled) return call.stopped();
    return Status(CodeOf(e.reason()), e.what());
  } catch (const reconstruction::ReconstructionError& e) {
    return Status(StatusCode::FAILED_PRECONDITION, e.what());
  } catch (const std::invalid_argument& e) {
    return Status(StatusCode::INVALID_ARGUMENT, e.what());
  } catch (const std::bad_alloc&) {
    return Status(StatusCode::RESOURCE_EXHAUSTED, call.name + ": out of memory");
  } catch (const std::exception& e) {
    spdlog::error("{}: internal error: {}", call.name, e.what());
    return Status(StatusCode::INTERNAL, call.name + ": internal error: " + e.what());
  }
  return Status::OK;
}

Status ProcessingService::Perform(const CallState& call, Work& w,
                                  const std::function<void(Work&)>& work) {
  if (call.gave_up()) return call.stopped();
  if (Status s = Guarded(call, [&] { work(w); }); !s.ok()) return s;
  w.result.set_software_version(options_.software_version);
  w.result.set_replica(options_.replica);
  w.Time("total",
         std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - w.start)
             .count());
  v1::WorkEvent done;
  *done.mutable_result() = std::move(w.result);
  if (!w.emit(done)) return call.stopped();
  return Status::OK;
}

grpc::ServerWriteReactor<v1::WorkEvent>* ProcessingService::StartWork(
    grpc::CallbackServerContext* context, const std::string& call,
    std::function<void(Work&)> work) {
  auto* stream = new internal::WorkStream();
  std::optional<WorkPool::Place> place;
  if (Status refused = Admit(&place); !refused.ok()) {
    stream->End(refused);
    return stream;
  }
  auto state = std::make_shared<CallState>(
      CallState{call, GaveUp(context, draining_, [stream] { return stream->cancelled(); }),
                Stopped(context, draining_, call)});
  // Cancelled while it waits: the job leaves the queue and the call ends now.
  stream->SetOnCancel([this, number = place->number()] { pool_.Cancel(number); });
  stream->Push(Progress("queued", 0.0));
  WorkPool::Job job;
  job.run = [this, stream, state, work = std::move(work)] {
    Work w([stream](const v1::WorkEvent& e) { return stream->Push(e); }, *state);
    Status status = Perform(*state, w, work);
    // What the call allocated goes back to the system (glibc keeps freed
    // blocks otherwise; a burst of calls would leave the replica large).
    rpc::ReturnFreedMemory();
    // The status goes out once the worker counts as free; the last use of
    // the stream.
    return std::function<void()>([stream, status] { stream->End(status); });
  };
  job.dropped = [stream, state] { stream->End(state->stopped()); };
  pool_.Start(std::move(*place), std::move(job));
  return stream;
}

Status ProcessingService::RunWaiting(grpc::ServerContext* context, const std::string& call,
                                     const Emit& emit, const std::function<void(Work&)>& prepare,
                                     const std::function<void(Work&)>& work) {
  std::optional<WorkPool::Place> place;
  if (Status refused = Admit(&place); !refused.ok()) return refused;
  const CallState state{call, GaveUp(context, draining_), Stopped(context, draining_, call)};
  if (!emit(Progress("queued", 0.0))) return state.stopped();
  Work w(emit, state);
  if (Status s = Guarded(state, [&] { prepare(w); }); !s.ok()) return s;
  // The work runs on a worker; this thread waits for it, and takes it out
  // of the queue when the caller gives up before it started.
  std::promise<Status> done;
  std::future<Status> status = done.get_future();
  const std::uint64_t number = place->number();
  WorkPool::Job job;
  job.run = [&] {
    Status s = Perform(state, w, work);
    rpc::ReturnFreedMemory();
    return std::function<void()>([&done, s] { done.set_value(s); });
  };
  job.dropped = [&] { done.set_value(state.stopped()); };
  pool_.Start(std::move(*place), std::move(job));
  while (status.wait_for(std::chrono::milliseconds(20)) != std::future_status::ready)
    if (state.gave_up()) pool_.Cancel(number);
  return status.get();
}

grpc::ServerWriteReactor<v1::WorkEvent>* ProcessingService::ProcessFrame(
    grpc::CallbackServerContext* context, const v1::ProcessFrameRequest* request) {
  return StartWork(context, "ProcessFrame", [this, request](Work& w) {
    // Every field is checked before any work.
    const cv::Mat grey = FrameOf(request->frame(), "frame", options_.max_frame_pixels);
    const pattern::Side side = contract::SideOf(request->side(), "side");
    CheckTag(request->request_tag());
    std::shared_ptr<const CachedCalibration> cal;
    if (request->calibration().source_case() != v1::CalibrationSource::SOURCE_NOT_SET)
      cal = ResolveCalibration(request->calibration(), "calibration");
    if (cal && request->geometric_setup())
      Refuse(StatusCode::INVALID_ARGUMENT, "geometric_setup: excludes a calibration");
    if (request->want_surface() && !cal && !request->geometric_setup())
      Refuse(StatusCode::INVALID_ARGUMENT,
             "want_surface: needs a calibration (or geometric_setup, the thesis's uncalibrated "
             "height formula)");
    reconstruction::SidePipelineParams params =
        contract::SideParams(request->decode(), request->surface());
    params.reconstruct = request->want_surface();
    params.decode.draw_tracks = request->want_skeleton();

    w.observer.CheckCancelled("the decode");
    w.observer.Report(request->want_surface() ? "decode and reconstruct" : "decode", 0.0);
    reconstruction::SideGeometry geometry;
    if (cal) geometry = &cal->calibration;
    if (request->geometric_setup()) geometry = reconstruction::GeometricSetupParams{};
    const reconstruction::SideOutcome outcome =
        reconstruction::ProcessSide(grey, side, geometry, params, w.observer.cancellation());
    const decoder::DecodeResult& d = outcome.decode;
    // The skeleton shows why a frame failed: sent before a refusal too.
    if (request->want_skeleton() && !d.skeleton.empty()) w.Png("skeleton.png", d.skeleton);
    if (!d.ok) Refuse(StatusCode::FAILED_PRECONDITION, "frame: " + d.error);
    w.observer.CheckCancelled("sending the results");
    w.observer.Report("results", 0.9);
    w.Artifact("junctions.json", "application/json", decoder::ToJson(d).dump(1) + "\n");
    if (request->want_overlay()) w.Png("overlay.png", decoder::RenderOverlay(grey, d));
    if (outcome.surface)
      w.Artifact("surface.ply", "application/x-ply",
                 io::EncodePly(*outcome.surface, request->surface().ascii_ply()
                                                     ? io::PlyEncoding::kAscii
                                                     : io::PlyEncoding::kBinaryLittleEndian));
    contract::FillSide(outcome, side, w.result.add_sides());
    if (cal) w.result.add_calibration_ids(cal->id);
    w.result.set_request_tag(request->request_tag());
    w.result.set_frame_sha256(PackedSha256(grey));
    w.Time("extraction", d.times.extraction_ms);
    w.Time("interpretation", d.times.interpretation_ms);
    w.Time("subpixel", d.times.subpixel_ms);
    w.Time("decode", d.times.total_ms);
    if (outcome.surface) w.Time("reconstruct", outcome.report.time_ms);
  });
}

grpc::ServerWriteReactor<v1::WorkEvent>* ProcessingService::ReconstructSession(
    grpc::CallbackServerContext* context, const v1::ReconstructSessionRequest* request) {
  return StartWork(context, "ReconstructSession", [this, request](Work& w) {
    const cv::Mat left = FrameOf(request->left(), "left", options_.max_frame_pixels);
    const cv::Mat right = FrameOf(request->right(), "right", options_.max_frame_pixels);
    CheckTag(request->request_tag());
    const auto left_cal = ResolveCalibration(request->left_calibration(), "left_calibration");
    const auto right_cal = ResolveCalibration(request->right_calibration(), "right_calibration");
    session::SessionParams params;
    params.side = contract::SideParams({}, request->surface());
    params.join = contract::JoinModeOf(request->join());
    params.measurements = contract::PlanOf(request->measurements(), options_.max_measurements);

    const session::SessionOutcome s = session::ReconstructSession(
        left, left_cal->calibration, right, right_cal->calibration, params, w.observer);
    w.observer.CheckCancelled("sending the results");
    w.observer.Report("results", 0.95);
    const auto encoding = request->surface().ascii_ply() ? io::PlyEncoding::kAscii
                                                         : io::PlyEncoding::kBinaryLittleEndian;
    if (request->want_junctions()) {
      w.Artifact("left.junctions.json", "application/json",
                 decoder::ToJson(s.left.decode).dump(1) + "\n");
      w.Artifact("right.junctions.json", "application/json",
                 decoder::ToJson(s.right.decode).dump(1) + "\n");
    }
    if (request->want_side_surfaces()) {
      w.Artifact("left.ply", "application/x-ply", io::EncodePly(*s.left.surface, encoding));
      w.Artifact("right.ply", "application/x-ply", io::EncodePly(*s.right.surface, encoding));
    }
    nlohmann::json report = session::SessionReport(s, "left", "right");
    report["calibrations"] = {{"left", left_cal->id}, {"right", right_cal->id}};
    report["frames_sha256"] = {{"left", PackedSha256(left)}, {"right", PackedSha256(right)}};
    report["software_version"] = options_.software_version;
    report["replica"] = options_.replica;
    w.Artifact("report.json", "application/json", report.dump(2) + "\n");
    if (s.measurements) {
      nlohmann::json m = s.measurements->report;
      m["table"] = measurement::FormatTable(s.measurements->rows, 2);
      w.Artifact("measurements.json", "application/json", m.dump(2) + "\n");
    }
    w.Artifact("surface.ply", "application/x-ply", io::EncodePly(s.joined.mesh, encoding));

    contract::FillSide(s.left, pattern::Side::kLeft, w.result.add_sides());
    contract::FillSide(s.right, pattern::Side::kRight, w.result.add_sides());
    w.result.add_calibration_ids(left_cal->id);
    w.result.add_calibration_ids(right_cal->id);
    w.result.set_request_tag(request->request_tag());
    w.result.set_join_method(s.by_features ? "features+icp" : "shared-frame");
    w.result.set_seam_rms_mm(s.joined.seam.rms_mm);
    w.result.set_seam_max_mm(s.joined.seam.max_mm);
    w.result.set_vertices(static_cast<std::uint32_t>(s.joined.mesh.VertexCount()));
    w.result.set_triangles(static_cast<std::uint32_t>(s.joined.mesh.faces.size()));
    w.Time("left decode", s.left.decode.times.total_ms);
    w.Time("left reconstruct", s.left.report.time_ms);
    w.Time("right decode", s.right.decode.times.total_ms);
    w.Time("right reconstruct", s.right.report.time_ms);
    w.Time("session", s.total_ms);
  });
}

grpc::ServerWriteReactor<v1::WorkEvent>* ProcessingService::Measure(
    grpc::CallbackServerContext* context, const v1::MeasureRequest* request) {
  return StartWork(context, "Measure", [this, request](Work& w) {
    CheckTag(request->request_tag());
    measurement::MeasurementPlan plan =
        contract::PlanOf(request->measurements(), options_.max_measurements);
    if (plan.empty())
      Refuse(StatusCode::INVALID_ARGUMENT, "measurements: give at least one figure");
    geometry::SurfaceMesh surface;
    try {
      surface = io::DecodePly(request->surface_ply(), "surface_ply");
      if (!request->baseline_ply().empty()) {
        plan.baseline = io::DecodePly(request->baseline_ply(), "baseline_ply");
        plan.baseline_name = "baseline_ply";
        plan.baseline_params.register_rigidly = !request->baseline_shares_frame();
      }
    } catch (const InputError& e) {
      Refuse(StatusCode::INVALID_ARGUMENT, e.what());
    }
    std::string why;
    if (!plan.IsValid(&why)) Refuse(StatusCode::INVALID_ARGUMENT, "measurements: " + why);
    w.observer.CheckCancelled("the measurements");
    w.observer.Report("measure", 0.0);
    measurement::MeasurementOutcome m;
    try {
      m = measurement::MeasurePlan(surface, plan, w.observer.cancellation());
    } catch (const measurement::MeasurementError& e) {
      Refuse(StatusCode::FAILED_PRECONDITION, std::string("surface_ply: ") + e.what());
    }
    m.report["table"] = measurement::FormatTable(m.rows, 2);
    w.Artifact("measurements.json", "application/json", m.report.dump(2) + "\n");
    w.result.set_request_tag(request->request_tag());
    w.result.set_vertices(static_cast<std::uint32_t>(surface.VertexCount()));
    w.result.set_triangles(static_cast<std::uint32_t>(surface.faces.size()));
  });
}

Status ProcessingService::CalibrateUpload(
    grpc::ServerContext* context,
    grpc::ServerReaderWriter<grpc::ByteBuffer, grpc::ByteBuffer>* raw) {
  UploadStream stream_parsed(raw);
  UploadStream* stream = &stream_parsed;
  const Emit emit = [stream](const v1::WorkEvent& e) { return stream->Write(e); };
  // The manifest comes first: without it there is nothing to queue for.
  v1::CalibrateRequest first;
  try {
    if (!stream->Read(&first))
      return Status(StatusCode::INVALID_ARGUMENT,
                    "Calibrate: the upload ended before the manifest");
  } catch (const Refusal& r) {
    return r.status;
  }
  if (Status refused = CheckManifestMessage(first, options_.max_manifest_bytes); !refused.ok())
    return refused;

  // The upload is taken while the call holds a queue place, before a worker.
  std::optional<ScratchFolder> scratch;
  const auto upload = [&](Work& w) {
    const ScratchFolder& folder = scratch.emplace(options_.scratch_dir);
    {
      std::ofstream manifest(folder.path() / "manifest.yaml", std::ios::binary);
      manifest << first.manifest().yaml();
      if (!manifest.flush())
        Refuse(StatusCode::INTERNAL, "cannot write the manifest to " + folder.path().string());
    }
    w.observer.Report("upload", 0.0);
    ReceiveUploadFiles(stream, folder.path(), options_, w.observer);
  };
  return RunWaiting(context, "Calibrate", emit, upload, [&](Work& w) {
    const ScratchFolder& folder = *scratch;
    // Paths in errors are the client's, not the scratch folder's.
    const std::string prefix = folder.path().string() + "/";
    const calibration::Manifest manifest =
        LoadUploadedManifest(folder.path(), first.manifest().yaml(), prefix);
    calibration::SideCalibration result;
    calibration::SideCalibrationParams params;
    params.images.max_pixels = options_.max_frame_pixels;  // images are frames: the same budget
    try {
      result = calibration::CalibrateSide(
          manifest, params,
          [&w](const std::string& view, double fraction) {
            if (w.observer.cancelled && w.observer.cancelled()) return false;
            w.observer.Report("calibrate " + view, 0.05 + 0.9 * fraction);
            return true;
          },
          w.observer.cancellation());
    } catch (const calibration::CalibrationError& e) {
      if (e.reason() == calibration::CalibrationErrorReason::kCancelled) throw;
      throw calibration::CalibrationError(e.reason(), WithoutPrefix(e.what(), prefix));
    }
    UseClientPaths(result, folder.path(), prefix);
    const std::string yaml = calibration::CalibrationToYaml(result, options_.software_version);
    const auto cached = calibrations_.Put(yaml, "the new calibration");
    nlohmann::json report = calibration::CalibrationReport(result);
    report["calibration_id"] = cached->id;
    w.Artifact("calibration-report.json", "application/json", report.dump(1) + "\n");
    w.Artifact("calibration.yaml", "application/yaml", yaml);
    w.result.set_calibration_id(cached->id);
    w.result.set_request_tag(first.manifest().request_tag());
    w.Time("calibrate", result.diagnostics.times.total_ms);
  });
}

Status ProcessingService::PutCalibration(grpc::ServerContext*,
                                         const v1::PutCalibrationRequest* request,
                                         v1::CalibrationInfo* response) {
  try {
    FillInfo(*calibrations_.Put(request->yaml(), "calibration"), response);
  } catch (const calibration::CalibrationFileError& e) {
    return Status(StatusCode::INVALID_ARGUMENT, e.what());
  }
  return Status::OK;
}

Status ProcessingService::GetCalibration(grpc::ServerContext*,
                                         const v1::GetCalibrationRequest* request,
                                         v1::CalibrationFile* response) {
  v1::CalibrationSource source;
  source.set_id(request->id());
  try {
    const auto found = ResolveCalibration(source, "id");
    FillInfo(*found, response->mutable_info());
    response->set_yaml(found->yaml);
  } catch (const Refusal& r) {
    return r.status;
  }
  return Status::OK;
}

Status ProcessingService::GetServerInfo(grpc::ServerContext*, const v1::GetServerInfoRequest*,
                                        v1::ServerInfo* response) {
  const WorkPoolStats s = pool_.Stats();
  response->set_software_version(options_.software_version);
  response->set_replica(options_.replica);
  response->set_workers(static_cast<std::uint32_t>(s.workers));
  response->set_queue(static_cast<std::uint32_t>(s.queue));
  response->set_busy(static_cast<std::uint32_t>(s.busy));
  response->set_waiting(static_cast<std::uint32_t>(s.waiting));
  response->set_completed(s.completed);
  response->set_rejected(s.rejected);
  response->set_cached_calibrations(static_cast<std::uint32_t>(calibrations_.size()));
  return Status::OK;
}

}  // namespace bsls::processing
