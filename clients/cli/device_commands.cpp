// The capture daemon's commands of `bsls` (for the bedside workstation and
// automation scripts): status, camera, gain, slide, grab,
// captures and preview, over the daemon's gRPC API (proto/bsls/v1).
// Every call has a deadline; --json prints the reply for scripts (frames
// without their pixels); frames are written as lossless PNG files.
#include <google/protobuf/util/json_util.h>

#include <filesystem>
#include <iostream>
#include <map>
#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>
#include <opencv2/highgui.hpp>

#include "bsls/common/atomic_file.h"
#include "bsls/contract/frame_message.h"
#include "bsls/io/frame_file.h"
#include "bsls/rpc/artifacts.h"
#include "bsls/v1/capture.grpc.pb.h"
#include "command.h"
#include "daemon_connection.h"

namespace bsls::cli {

namespace {

namespace fs = std::filesystem;

const std::map<std::string, v1::Camera> kCameras = {
    {"left", v1::CAMERA_LEFT}, {"right", v1::CAMERA_RIGHT}, {"third", v1::CAMERA_THIRD}};
const std::map<std::string, v1::GrabSide> kSides = {
    {"left", v1::GRAB_SIDE_LEFT}, {"right", v1::GRAB_SIDE_RIGHT}, {"both", v1::GRAB_SIDE_BOTH}};
// Slides by name or number (thesis 2.4).
const std::map<std::string, int> kSlides = {{"reference", 1}, {"1", 1},     {"left", 2},
                                            {"2", 2},         {"right", 3}, {"3", 3}};

// The name under which `names` holds `value`; "unspecified" when none.
template <typename Enum>
std::string NameOf(const std::map<std::string, Enum>& names, Enum value) {
  for (const auto& [name, entry] : names)
    if (entry == value) return name;
  return "unspecified";
}

std::string CameraName(v1::Camera camera) { return NameOf(kCameras, camera); }
std::string SideName(v1::GrabSide side) { return NameOf(kSides, side); }

// Creates the output folder `dir` (of option -o); CommandError (exit 4) when it cannot.
void MakeFolder(const std::string& dir) {
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec)
    throw CommandError(kExitOutput, "-o " + dir + ": cannot create the folder: " + ec.message());
}

// The frame's pixels as an image (no copy); CommandError (exit 7) naming
// `what` when the message does not hold the frame its size says.
cv::Mat FrameImage(const v1::Frame& frame, const std::string& what) {
  try {
    return contract::FrameView(frame, what);
  } catch (const contract::MessageError& e) {
    throw CommandError(kExitServiceFailed, std::string(e.what()) + " (damaged in transit?)");
  }
}

// The message as one line of JSON with the proto's field names.
std::string Json(const google::protobuf::Message& message) {
  google::protobuf::util::JsonPrintOptions options;
  options.preserve_proto_field_names = true;
  std::string out;
  if (!google::protobuf::util::MessageToJsonString(message, &out, options).ok())
    throw CommandError(kExitInternal, "a reply could not be printed as JSON");
  return out;
}

// A capture without pixels, for printing.
v1::CaptureInfo WithoutPixels(v1::CaptureInfo info) {
  for (v1::Frame& frame : *info.mutable_frames()) frame.clear_pixels();
  return info;
}

std::string Describe(const v1::SlideState& slide) {
  static const char* kNames[] = {"none", "reference", "left pattern", "right pattern"};
  std::string out = "slide " + std::to_string(slide.slide());
  if (slide.slide() >= 0 && slide.slide() <= 3)
    out += std::string(" (") + kNames[slide.slide()] + ")";
  out += slide.in_place() ? ", in place" : (slide.moving() ? ", moving" : ", not confirmed");
  out += std::string(", lamp ") + (slide.lamp_on() ? "on" : "off");
  out += ", focus " + std::to_string(slide.focus_position());
  if (!slide.last_error().empty()) out += ", last error: " + slide.last_error();
  return out;
}

void PrintStatus(const v1::DeviceStatus& status, bool json) {
  if (json) {
    std::cout << Json(status) << "\n";
    return;
  }
  std::cout << "device:    " << status.backend() << " — " << status.device()
            << (status.available() ? "" : " (UNAVAILABLE: " + status.availability_reason() + ")")
            << "\n";
  std::cout << "cameras:  ";
  for (int c : status.cameras()) std::cout << " " << CameraName(static_cast<v1::Camera>(c));
  std::cout << " (selected " << CameraName(status.selected_camera()) << ")\n";
  std::cout << "frame:     " << status.width() << " x " << status.height() << " at "
            << status.preview_rate_hz() << " Hz\n";
  std::cout << "gain:      " << status.gain() << " (" << status.gain_range().min() << ".."
            << status.gain_range().max() << ", nominal " << status.gain_range().nominal() << ")\n";
  std::cout << "slides:    " << Describe(status.slide()) << "\n";
  std::cout << "store:     " << status.captures_stored() << " captures, "
            << status.store_free_bytes() / (1 << 20) << " MiB free\n";
  std::cout << "you:       " << status.caller_role() << "\n";
  std::cout << "daemon:    bslsd " << status.software_version() << "\n";
}

// Writes each frame of `info` as DIR/<capture id>_<camera>.png; the paths.
std::vector<std::string> WriteFrames(const v1::CaptureInfo& info, const std::string& dir) {
  MakeFolder(dir);
  std::vector<std::string> paths;
  for (const v1::Frame& frame : info.frames()) {
    const cv::Mat view = FrameImage(frame, "capture " + info.capture_id());
    const std::string path =
        (fs::path(dir) / (info.capture_id() + "_" + CameraName(frame.camera()) + ".png")).string();
    io::WritePngAtomically(path, view);
    paths.push_back(path);
  }
  return paths;
}

void PrintCapture(const v1::CaptureInfo& info, const std::vector<std::string>& files, bool json) {
  if (json) {
    std::cout << Json(WithoutPixels(info)) << "\n";
    return;
  }
  std::cout << info.capture_id() << "  " << SideName(info.side()) << "  slide " << info.slide()
            << "  session '" << info.session_id() << "'  patient '" << info.patient_reference()
            << "'  by " << info.requested_by() << "\n";
  for (const v1::Frame& frame : info.frames())
    std::cout << "  " << CameraName(frame.camera()) << ": " << frame.width() << " x "
              << frame.height() << ", gain " << frame.gain() << ", sha256 " << frame.sha256()
              << "\n";
  if (info.has_processing()) {
    static const std::map<int, std::string> kStates = {
        {v1::ProcessingStatus::STATE_PENDING, "pending"},
        {v1::ProcessingStatus::STATE_DONE, "done"},
        {v1::ProcessingStatus::STATE_FAILED, "failed"},
        {v1::ProcessingStatus::STATE_DISABLED, "not configured"}};
    const v1::ProcessingStatus& p = info.processing();
    const auto state = kStates.find(p.state());
    std::cout << "  processing: " << (state != kStates.end() ? state->second : "unknown");
    if (p.attempts() > 0) std::cout << ", " << p.attempts() << " attempts";
    if (!p.replica().empty()) std::cout << ", by " << p.replica();
    if (p.files_size() > 0) std::cout << ", " << p.files_size() << " result files";
    if (!p.last_error().empty()) std::cout << ": " << p.last_error();
    std::cout << "\n";
  }
  for (const std::string& file : files) std::cout << "  wrote " << file << "\n";
}

struct DeviceOptions {
  ServiceAddress address;
  bool json = false;
};

// A subcommand with the daemon options and --json.
CLI::App* AddDeviceCommand(CLI::App& app, const std::string& name, const std::string& help,
                           DeviceOptions& options) {
  CLI::App* command = app.add_subcommand(name, help);
  AddDaemonOptions(*command, options.address);
  command->add_flag("--json", options.json, "print the reply as JSON (for scripts)");
  return command;
}

std::unique_ptr<v1::CaptureDaemon::Stub> Connect(const DeviceOptions& options) {
  return v1::CaptureDaemon::NewStub(OpenChannel(options.address));
}

using SharedOptions = std::shared_ptr<DeviceOptions>;

// bsls status: the daemon's device, slides and store.
void AddStatusCommand(CLI::App& app, const SharedOptions& options) {
  CLI::App* status =
      AddDeviceCommand(app, "status", "the capture daemon's device, slides and store", *options);
  status->callback([options] {
    v1::DeviceStatus reply;
    CheckCall(Connect(*options)->GetStatus(CallContext(options->address).get(), {}, &reply),
              "GetStatus", options->address);
    PrintStatus(reply, options->json);
  });
}

// bsls camera CAMERA: selects the camera of previews and one-side grabs.
void AddCameraCommand(CLI::App& app, const SharedOptions& options) {
  auto camera = std::make_shared<std::string>();
  CLI::App* camera_command =
      AddDeviceCommand(app, "camera", "select the camera of previews and one-side grabs", *options);
  camera_command->add_option("CAMERA", *camera, "left, right or third")
      ->required()
      ->check(CLI::IsMember({"left", "right", "third"}));
  camera_command->callback([options, camera] {
    v1::SelectCameraRequest request;
    request.set_camera(kCameras.at(*camera));
    v1::DeviceStatus reply;
    CheckCall(Connect(*options)->SelectCamera(CallContext(options->address).get(), request, &reply),
              "SelectCamera", options->address);
    PrintStatus(reply, options->json);
  });
}

// bsls gain GAIN: sets the cameras' manual gain.
void AddGainCommand(CLI::App& app, const SharedOptions& options) {
  auto gain = std::make_shared<int>(0);
  CLI::App* gain_command = AddDeviceCommand(app, "gain", "set the cameras' manual gain", *options);
  gain_command->add_option("GAIN", *gain, "inside the range `bsls status` shows")->required();
  gain_command->callback([options, gain] {
    v1::SetGainRequest request;
    request.set_gain(*gain);
    v1::DeviceStatus reply;
    CheckCall(Connect(*options)->SetGain(CallContext(options->address).get(), request, &reply),
              "SetGain", options->address);
    PrintStatus(reply, options->json);
  });
}

struct SlideArgs {
  std::string slide, lamp;
  int focus = 0;
};

// Sets the lamp, the slide and the focus as asked, in that order; without
// any, reads the slide state. Prints the state the last call returned.
void RunSlide(const DeviceOptions& options, const SlideArgs& args) {
  auto stub = Connect(options);
  v1::SlideState state;
  bool changed = false;
  if (!args.lamp.empty()) {
    v1::SetLampRequest request;
    request.set_on(args.lamp == "on");
    CheckCall(stub->SetLamp(CallContext(options.address).get(), request, &state), "SetLamp",
              options.address);
    changed = true;
  }
  if (!args.slide.empty()) {
    v1::SetSlideRequest request;
    request.set_slide(kSlides.at(args.slide));
    CheckCall(stub->SetSlide(CallContext(options.address).get(), request, &state), "SetSlide",
              options.address);
    changed = true;
  }
  if (args.focus != 0) {
    v1::SetFocusRequest request;
    request.set_steps(args.focus);
    CheckCall(stub->SetFocus(CallContext(options.address).get(), request, &state), "SetFocus",
              options.address);
    changed = true;
  }
  if (!changed)
    CheckCall(stub->GetSlideState(CallContext(options.address).get(), {}, &state), "GetSlideState",
              options.address);
  std::cout << (options.json ? Json(state) : Describe(state)) << "\n";
}

// bsls slide [SLIDE] [--focus STEPS] [--lamp on|off]: without arguments, the state.
void AddSlideCommand(CLI::App& app, const SharedOptions& options) {
  auto slide_args = std::make_shared<SlideArgs>();
  CLI::App* slide = AddDeviceCommand(
      app, "slide", "put a slide in place (reference|left|right or 1|2|3), focus, lamp", *options);
  slide->add_option("SLIDE", slide_args->slide, "reference (1), left (2) or right (3)")
      ->check(CLI::IsMember({"reference", "left", "right", "1", "2", "3"}));
  slide->add_option("--focus", slide_args->focus, "move the focus by signed motor steps")
      ->check(CLI::Range(-1000, 1000));
  slide->add_option("--lamp", slide_args->lamp, "switch the projector lamp")
      ->check(CLI::IsMember({"on", "off"}));
  slide->callback([options, slide_args] { RunSlide(*options, *slide_args); });
}

// bsls grab [--side S] [--session ID] [--patient REF] [-o DIR]: grabs and
// prints the stored capture, writing its frames with -o.
void AddGrabCommand(CLI::App& app, const SharedOptions& options) {
  struct GrabArgs {
    std::string side = "both", session, patient, out;
  };
  auto grab_args = std::make_shared<GrabArgs>();
  CLI::App* grab = AddDeviceCommand(
      app, "grab", "grab one side or both; the daemon stores it before answering", *options);
  grab->add_option("--side", grab_args->side, "left, right or both")
      ->check(CLI::IsMember({"left", "right", "both"}));
  grab->add_option("--session", grab_args->session, "session id stored with the capture");
  grab->add_option("--patient", grab_args->patient, "patient reference (never a name)");
  grab->add_option("-o,--out", grab_args->out, "also write the frames as PNG into this folder");
  grab->callback([options, grab_args] {
    v1::GrabRequest request;
    request.set_side(kSides.at(grab_args->side));
    request.set_session_id(grab_args->session);
    request.set_patient_reference(grab_args->patient);
    request.set_include_frames(!grab_args->out.empty());
    v1::GrabResponse reply;
    CheckCall(Connect(*options)->Grab(CallContext(options->address).get(), request, &reply), "Grab",
              options->address);
    std::vector<std::string> files;
    if (!grab_args->out.empty()) files = WriteFrames(reply.capture(), grab_args->out);
    PrintCapture(reply.capture(), files, options->json);
  });
}

// bsls captures list [--session ID] [--patient REF]: every page of them.
void AddListCommand(CLI::App& captures, const SharedOptions& options) {
  struct ListArgs {
    std::string session, patient;
  };
  auto list_args = std::make_shared<ListArgs>();
  CLI::App* list = AddDeviceCommand(captures, "list", "stored captures, oldest first", *options);
  list->add_option("--session", list_args->session, "only this session");
  list->add_option("--patient", list_args->patient, "only this patient reference");
  list->callback([options, list_args] {
    auto stub = Connect(*options);
    v1::ListCapturesRequest request;
    request.set_session_id(list_args->session);
    request.set_patient_reference(list_args->patient);
    request.set_page_size(1000);
    do {
      v1::ListCapturesResponse reply;
      CheckCall(stub->ListCaptures(CallContext(options->address).get(), request, &reply),
                "ListCaptures", options->address);
      for (const v1::CaptureInfo& info : reply.captures()) PrintCapture(info, {}, options->json);
      request.set_page_token(reply.next_page_token());
    } while (!request.page_token().empty());
  });
}

struct GetArgs {
  std::string id, out;
};

// bsls captures get ID [-o DIR]: one capture, its frames written with -o.
void AddGetCommand(CLI::App& captures, const SharedOptions& options) {
  auto get_args = std::make_shared<GetArgs>();
  CLI::App* get = AddDeviceCommand(captures, "get", "one capture; -o writes its frames", *options);
  get->add_option("CAPTURE_ID", get_args->id, "32 hex digits")->required();
  get->add_option("-o,--out", get_args->out, "write the frames as PNG into this folder");
  get->callback([options, get_args] {
    v1::GetCaptureRequest request;
    request.set_capture_id(get_args->id);
    v1::CaptureInfo info;
    CheckCall(Connect(*options)->GetCapture(CallContext(options->address).get(), request, &info),
              "GetCapture", options->address);
    std::vector<std::string> files;
    if (!get_args->out.empty()) files = WriteFrames(info, get_args->out);
    PrintCapture(info, files, options->json);
  });
}

// Streams the capture's result files and writes them into args.out, naming
// each file written; CommandError when the stream fails or is damaged.
void FetchResults(const DeviceOptions& options, const GetArgs& args) {
  v1::GetCaptureResultRequest request;
  request.set_capture_id(args.id);
  auto context = CallContext(options.address);
  auto reader = Connect(options)->GetCaptureResult(context.get(), request);
  rpc::ArtifactAssembler assembler;
  v1::Artifact chunk;
  std::string damage;
  while (reader->Read(&chunk)) {
    if (!damage.empty()) continue;
    try {
      assembler.Add(chunk);
    } catch (const rpc::ArtifactError& e) {
      damage = e.what();
    }
  }
  CheckCall(reader->Finish(), "GetCaptureResult", options.address);
  if (!damage.empty()) throw CommandError(kExitServiceFailed, "GetCaptureResult: " + damage);
  MakeFolder(args.out);
  for (const auto& [name, bytes] : assembler.files()) {
    const std::string path = args.out + "/" + name;
    WriteFileAtomically(path, bytes);
    if (options.json)
      std::cout << nlohmann::json{{"file", path}, {"bytes", bytes.size()}}.dump() << "\n";
    else
      std::cout << "wrote " << path << " (" << bytes.size() << " bytes)\n";
  }
}

// bsls captures results ID -o DIR: the processing results kept with the capture.
void AddResultsCommand(CLI::App& captures, const SharedOptions& options) {
  auto results_args = std::make_shared<GetArgs>();
  CLI::App* results = AddDeviceCommand(
      captures, "results", "the processing results kept with a capture (surface, reports, record)",
      *options);
  results->add_option("CAPTURE_ID", results_args->id, "32 hex digits")->required();
  results->add_option("-o,--out", results_args->out, "folder for the files")->required();
  results->callback([options, results_args] { FetchResults(*options, *results_args); });
}

// bsls captures delete ID: deletes one capture (admin).
void AddDeleteCommand(CLI::App& captures, const SharedOptions& options) {
  auto delete_id = std::make_shared<std::string>();
  CLI::App* remove = AddDeviceCommand(captures, "delete", "delete one capture (admin)", *options);
  remove->add_option("CAPTURE_ID", *delete_id, "32 hex digits")->required();
  remove->callback([options, delete_id] {
    v1::DeleteCaptureRequest request;
    request.set_capture_id(*delete_id);
    v1::DeleteCaptureResponse reply;
    CheckCall(
        Connect(*options)->DeleteCapture(CallContext(options->address).get(), request, &reply),
        "DeleteCapture", options->address);
    if (!options->json)
      std::cout << "deleted " << *delete_id << "\n";
    else
      std::cout << "{\"deleted\":\"" << *delete_id << "\"}\n";
  });
}

struct PreviewArgs {
  std::string camera, out;
  int frames = 25;
  bool show = false;
};

// Takes args.frames preview frames (fewer when the window is closed with q
// or Esc), writing each with -o and showing it with --show; prints what it
// took.
void RunPreview(const DeviceOptions& options, const PreviewArgs& args) {
  if (args.out.empty() && !args.show)
    throw CommandError(kExitUsage, "preview: give -o DIR (write the frames) or --show");
  if (args.show && std::getenv("DISPLAY") == nullptr && std::getenv("WAYLAND_DISPLAY") == nullptr)
    throw CommandError(kExitUsage, "preview --show: no display (DISPLAY is not set); use -o DIR");
  if (!args.out.empty()) MakeFolder(args.out);
  v1::PreviewRequest request;
  if (!args.camera.empty()) request.set_camera(kCameras.at(args.camera));
  // The stream's deadline covers every frame asked for, at 25 Hz, plus the timeout.
  ServiceAddress address = options.address;
  address.timeout_s += args.frames / 25.0;
  auto context = CallContext(address);
  auto reader = Connect(options)->StreamPreview(context.get(), request);
  v1::PreviewFrame message;
  int taken = 0;
  std::uint64_t dropped = 0;
  const auto start = std::chrono::steady_clock::now();
  while (taken < args.frames && reader->Read(&message)) {
    const cv::Mat view = FrameImage(message.frame(), "preview");
    if (!args.out.empty()) {
      char name[32];
      std::snprintf(name, sizeof name, "preview_%05d.png", taken);
      io::WritePngAtomically((fs::path(args.out) / name).string(), view);
    }
    dropped += message.dropped();
    ++taken;
    if (args.show) {
      cv::imshow("bsls preview", view);
      const int key = cv::waitKey(1);
      if (key == 'q' || key == 27) break;
    }
  }
  context->TryCancel();
  const grpc::Status finished = reader->Finish();
  if (taken < args.frames) CheckCall(finished, "StreamPreview", options.address);
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (options.json)
    std::cout << "{\"frames\":" << taken << ",\"dropped\":" << dropped << ",\"seconds\":" << seconds
              << "}\n";
  else if (!args.out.empty())
    std::cout << "wrote " << taken << " frames to " << args.out << " in " << seconds << " s ("
              << dropped << " skipped while writing)\n";
  else
    std::cout << "showed " << taken << " frames in " << seconds << " s (" << dropped
              << " skipped)\n";
}

// bsls preview [--camera C] [--frames N] [-o DIR] [--show]: live frames.
void AddPreviewCommand(CLI::App& app, const SharedOptions& options) {
  auto preview_args = std::make_shared<PreviewArgs>();
  CLI::App* preview = AddDeviceCommand(
      app, "preview", "live frames of one camera, written as PNG files or shown in a window",
      *options);
  preview->add_option("--camera", preview_args->camera, "left, right or third (default: selected)")
      ->check(CLI::IsMember({"left", "right", "third"}));
  preview->add_option("--frames", preview_args->frames, "how many frames to take")
      ->check(CLI::Range(1, 100000));
  preview->add_option("-o,--out", preview_args->out, "folder for preview_NNNNN.png");
  preview->add_flag("--show", preview_args->show,
                    "show the frames in a window (positioning the patient); q or Esc ends");
  preview->callback([options, preview_args] { RunPreview(*options, *preview_args); });
}

}  // namespace

void AddDeviceCommands(CLI::App& app) {
  auto options = std::make_shared<DeviceOptions>();
  AddStatusCommand(app, options);
  AddCameraCommand(app, options);
  AddGainCommand(app, options);
  AddSlideCommand(app, options);
  AddGrabCommand(app, options);

  // bsls captures list|get|results|delete
  CLI::App* captures = app.add_subcommand("captures", "the daemon's stored captures");
  captures->require_subcommand(1);
  AddListCommand(*captures, options);
  AddGetCommand(*captures, options);
  AddResultsCommand(*captures, options);
  AddDeleteCommand(*captures, options);

  AddPreviewCommand(app, options);
}

}  // namespace bsls::cli
