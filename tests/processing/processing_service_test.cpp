// bsls-processd's service through gRPC (in-process channel): the three work
// calls against the simulator, the calibration cache, the bounded pool,
// cancellation and deadlines, and every kind of bad request.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <future>
#include <memory>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <thread>

#include "bsls/contract/processing_messages.h"
#include "bsls/decoder/decode_output.h"
#include "bsls/decoder/decoder.h"
#include "bsls/io/surface_file.h"
#include "bsls/simulator/calibration_session.h"
#include "bsls/testing/hostile_frame.h"
#include "raw_calls.h"
#include "service_fixture.h"

namespace bsls::processing::test {
namespace {

namespace fs = std::filesystem;
using grpc::StatusCode;

v1::ProcessFrameRequest FaceRequest(pattern::Side side, bool with_calibration) {
  v1::ProcessFrameRequest request;
  *request.mutable_frame() = FrameMessage(FaceFrame(side));
  request.set_side(contract::ToProto(side));
  if (with_calibration) {
    *request.mutable_calibration() = ProcessingClient::Inline(CalibrationYaml(side));
    request.set_want_surface(true);
  }
  return request;
}

v1::ReconstructSessionRequest SessionRequest() {
  v1::ReconstructSessionRequest request;
  *request.mutable_left() = FrameMessage(FaceFrame(pattern::Side::kLeft));
  *request.mutable_right() = FrameMessage(FaceFrame(pattern::Side::kRight));
  *request.mutable_left_calibration() =
      ProcessingClient::Inline(CalibrationYaml(pattern::Side::kLeft));
  *request.mutable_right_calibration() =
      ProcessingClient::Inline(CalibrationYaml(pattern::Side::kRight));
  return request;
}

// The status of a work call made with a plain stub (no client retries).
template <typename Request>
grpc::Status CallFrame(InProcessService& s, const Request& request) {
  ProcessingClient client = s.Client();
  if constexpr (std::is_same_v<Request, v1::ProcessFrameRequest>)
    return client.ProcessFrame(request).status;
  else
    return client.ReconstructSession(request).status;
}

TEST(ProcessingService, ProcessFrameDecodesAndReconstructsOneSide) {
  InProcessService s;
  v1::ProcessFrameRequest request = FaceRequest(pattern::Side::kLeft, true);
  request.set_want_overlay(true);
  request.set_request_tag("bed 3");
  std::vector<std::string> stages;
  const WorkOutcome out =
      s.Client().ProcessFrame(request, [&](const v1::Progress& p) { stages.push_back(p.stage()); });
  ASSERT_TRUE(out.status.ok()) << out.status.error_message();
  ASSERT_FALSE(stages.empty());
  EXPECT_EQ(stages.front(), "queued");
  ASSERT_EQ(out.result.sides_size(), 1);
  const v1::SideSummary& side = out.result.sides(0);
  EXPECT_TRUE(side.q_absolute()) << side.rows_note();
  EXPECT_GT(side.junctions(), 300u);
  EXPECT_GT(side.vertices(), 5000u);
  EXPECT_EQ(out.result.request_tag(), "bed 3");
  EXPECT_EQ(out.result.replica(), "replica-under-test");
  ASSERT_EQ(out.result.calibration_ids_size(), 1);
  EXPECT_EQ(out.result.calibration_ids(0),
            CalibrationCache::IdOf(CalibrationYaml(pattern::Side::kLeft)));
  EXPECT_EQ(out.result.frame_sha256().size(), 64u);

  // The files are the contracts' outputs and agree with the summary.
  ASSERT_TRUE(out.files.count("junctions.json"));
  const nlohmann::json junctions = nlohmann::json::parse(out.files.at("junctions.json"));
  EXPECT_EQ(junctions.at("junctions").size(), side.junctions());
  const geometry::SurfaceMesh mesh = io::DecodePly(out.files.at("surface.ply"), "surface.ply");
  EXPECT_EQ(mesh.VertexCount(), side.vertices());
  const std::string& png = out.files.at("overlay.png");
  const cv::Mat overlay =
      cv::imdecode(std::vector<unsigned char>(png.begin(), png.end()), cv::IMREAD_COLOR);
  EXPECT_EQ(overlay.cols, FaceFrame(pattern::Side::kLeft).cols);
  // The calibration sent inline is now cached by its id.
  EXPECT_EQ(s.service().calibrations().size(), 1u);
}

// Either chain decodes on the service, and the same as here: the skeleton
// chain when named or asked for the thesis's extraction, the track chain by
// default.
TEST(ProcessingService, ProcessFrameDecodesByTheChainAskedFor) {
  InProcessService s;
  const cv::Mat frame = FaceFrame(pattern::Side::kRight);
  auto junctions_of = [&](v1::DecodeOptions::Chain chain, v1::DecodeOptions::Method method) {
    v1::ProcessFrameRequest request = FaceRequest(pattern::Side::kRight, false);
    request.mutable_decode()->set_chain(chain);
    request.mutable_decode()->set_method(method);
    const WorkOutcome out = s.Client().ProcessFrame(request);
    EXPECT_TRUE(out.status.ok()) << out.status.error_message();
    return out.files.count("junctions.json") ? nlohmann::json::parse(out.files.at("junctions.json"))
                                             : nlohmann::json();
  };
  auto local = [&](decoder::DecodeChain chain, extraction::ExtractionMethod method) {
    decoder::DecodeParams params;
    params.chain = chain;
    params.extraction.method = method;
    return decoder::ToJson(decoder::Decode(frame, pattern::Side::kRight, params));
  };
  using extraction::ExtractionMethod;
  const nlohmann::json tracks = local(decoder::DecodeChain::kTracks, ExtractionMethod::kModern);
  const nlohmann::json skeleton = local(decoder::DecodeChain::kSkeleton, ExtractionMethod::kModern);
  const nlohmann::json thesis = local(decoder::DecodeChain::kSkeleton, ExtractionMethod::kThesis);
  ASSERT_NE(tracks["junctions"], skeleton["junctions"]);
  const struct {
    v1::DecodeOptions::Chain chain;
    v1::DecodeOptions::Method method;
    const nlohmann::json& expected;
  } cases[] = {
      {v1::DecodeOptions::CHAIN_UNSPECIFIED, v1::DecodeOptions::METHOD_UNSPECIFIED, tracks},
      {v1::DecodeOptions::CHAIN_TRACKS, v1::DecodeOptions::METHOD_MODERN, tracks},
      {v1::DecodeOptions::CHAIN_SKELETON, v1::DecodeOptions::METHOD_UNSPECIFIED, skeleton},
      {v1::DecodeOptions::CHAIN_UNSPECIFIED, v1::DecodeOptions::METHOD_THESIS, thesis},
  };
  for (const auto& c : cases)
    EXPECT_EQ(junctions_of(c.chain, c.method)["junctions"], c.expected["junctions"])
        << "chain " << c.chain << ", method " << c.method;
}

TEST(ProcessingService, ProcessFrameWithoutCalibrationDecodesOnly) {
  InProcessService s;
  const WorkOutcome out = s.Client().ProcessFrame(FaceRequest(pattern::Side::kRight, false));
  ASSERT_TRUE(out.status.ok()) << out.status.error_message();
  EXPECT_FALSE(out.result.sides(0).q_absolute());
  EXPECT_TRUE(out.files.count("junctions.json"));
  EXPECT_FALSE(out.files.count("surface.ply"));
}

TEST(ProcessingService, ReconstructSessionJoinsAndMeasures) {
  InProcessService s;
  v1::ReconstructSessionRequest request = SessionRequest();
  request.set_want_side_surfaces(true);
  request.set_want_junctions(true);
  // The nose tip region and a height beside it (world mm, contracts 3).
  v1::MeasurementPlan* plan = request.mutable_measurements();
  v1::PointXY* h = plan->add_heights();
  h->set_x(0);
  h->set_y(-60);
  v1::Polygon* area = plan->add_areas();
  for (auto [x, y] : {std::pair{-10.0, -50.0}, {10.0, -50.0}, {10.0, -70.0}, {-10.0, -70.0}}) {
    v1::PointXY* p = area->add_points();
    p->set_x(x);
    p->set_y(y);
  }
  double last_fraction = -1;
  bool ordered = true;
  const WorkOutcome out = s.Client().ReconstructSession(request, [&](const v1::Progress& p) {
    ordered = ordered && p.fraction() >= last_fraction;
    last_fraction = p.fraction();
  });
  ASSERT_TRUE(out.status.ok()) << out.status.error_message();
  EXPECT_TRUE(ordered);
  EXPECT_EQ(out.result.join_method(), "shared-frame");
  EXPECT_LT(out.result.seam_rms_mm(), 0.3);
  EXPECT_EQ(out.result.sides_size(), 2);
  for (const char* name : {"surface.ply", "left.ply", "right.ply", "report.json",
                           "measurements.json", "left.junctions.json", "right.junctions.json"})
    EXPECT_TRUE(out.files.count(name)) << name;
  const geometry::SurfaceMesh joined = io::DecodePly(out.files.at("surface.ply"), "surface.ply");
  EXPECT_EQ(joined.VertexCount(), out.result.vertices());
  const nlohmann::json report = nlohmann::json::parse(out.files.at("report.json"));
  EXPECT_EQ(report.at("calibrations").at("left"), out.result.calibration_ids(0));
  EXPECT_EQ(report.at("software_version"), "test");
  const nlohmann::json m = nlohmann::json::parse(out.files.at("measurements.json"));
  ASSERT_EQ(m.at("heights").size(), 1u);
  EXPECT_GT(m.at("heights")[0].at("height_mm").at("value").get<double>(), 0.0);
  ASSERT_EQ(m.at("areas").size(), 1u);
  // A 20 x 20 mm square on a curved face: at least its flat area.
  EXPECT_GT(m.at("areas")[0].at("area_mm2").at("value").get<double>(), 399.0);

  // Measure: the same figures on the returned surface agree.
  v1::MeasureRequest measure;
  measure.set_surface_ply(out.files.at("surface.ply"));
  *measure.mutable_measurements() = request.measurements();
  const WorkOutcome measured = s.Client().Measure(measure);
  ASSERT_TRUE(measured.status.ok()) << measured.status.error_message();
  const nlohmann::json again = nlohmann::json::parse(measured.files.at("measurements.json"));
  EXPECT_NEAR(again.at("heights")[0].at("height_mm").at("value").get<double>(),
              m.at("heights")[0].at("height_mm").at("value").get<double>(),
              1e-4);  // mm: the PLY holds float32
  EXPECT_FALSE(again.at("table").get<std::string>().empty());
  measure.set_surface_ply("ply\nnonsense");
  EXPECT_EQ(s.Client().Measure(measure).status.error_code(), StatusCode::INVALID_ARGUMENT);
  measure.set_surface_ply(out.files.at("surface.ply"));
  measure.clear_measurements();
  EXPECT_EQ(s.Client().Measure(measure).status.error_code(), StatusCode::INVALID_ARGUMENT);
  v1::PointXY* far = measure.mutable_measurements()->add_heights();
  far->set_x(5000);
  far->set_y(5000);
  EXPECT_EQ(s.Client().Measure(measure).status.error_code(), StatusCode::FAILED_PRECONDITION);
}

TEST(ProcessingService, BadRequestsAreRefusedWithTheFieldNamed) {
  InProcessService s;
  struct Case {
    std::string name;
    std::function<void(v1::ProcessFrameRequest&)> damage;
    StatusCode code;
    std::string says;
  };
  const std::vector<Case> cases = {
      {"short pixels", [](auto& r) { r.mutable_frame()->mutable_pixels()->resize(100); },
       StatusCode::INVALID_ARGUMENT, "frame"},
      {"zero width", [](auto& r) { r.mutable_frame()->set_width(0); }, StatusCode::INVALID_ARGUMENT,
       "frame"},
      {"huge", [](auto& r) { r.mutable_frame()->set_height(100000); }, StatusCode::INVALID_ARGUMENT,
       "4096"},
      {"stride below width", [](auto& r) { r.mutable_frame()->set_stride(3); },
       StatusCode::INVALID_ARGUMENT, "stride"},
      {"no side", [](auto& r) { r.set_side(v1::SIDE_UNSPECIFIED); }, StatusCode::INVALID_ARGUMENT,
       "side"},
      {"surface without calibration",
       [](auto& r) {
         r.clear_calibration();
         r.set_want_surface(true);
       },
       StatusCode::INVALID_ARGUMENT, "want_surface"},
      {"unknown calibration id",
       [](auto& r) { r.mutable_calibration()->set_id("sha256:" + std::string(64, 'a')); },
       StatusCode::NOT_FOUND, "does not hold"},
      {"garbage calibration",
       [](auto& r) { r.mutable_calibration()->set_yaml("format: [unclosed"); },
       StatusCode::INVALID_ARGUMENT, "calibration"},
      {"calibration of the other side",
       [](auto& r) {
         *r.mutable_calibration() =
             ProcessingClient::Inline(CalibrationYaml(pattern::Side::kRight));
       },
       StatusCode::INVALID_ARGUMENT, "right"},
      {"all black",
       [](auto& r) {
         std::fill(r.mutable_frame()->mutable_pixels()->begin(),
                   r.mutable_frame()->mutable_pixels()->end(), 0);
       },
       StatusCode::FAILED_PRECONDITION, "frame"},
      {"long tag", [](auto& r) { r.set_request_tag(std::string(300, 'x')); },
       StatusCode::INVALID_ARGUMENT, "request_tag"},
      {"track chain with the thesis's extraction",
       [](auto& r) {
         r.mutable_decode()->set_chain(v1::DecodeOptions::CHAIN_TRACKS);
         r.mutable_decode()->set_method(v1::DecodeOptions::METHOD_THESIS);
       },
       StatusCode::INVALID_ARGUMENT, "decode.chain"},
      // Numbers the .proto does not define (proto3 keeps them): refused, not
      // read as the default.
      {"undefined chain",
       [](auto& r) { r.mutable_decode()->set_chain(static_cast<v1::DecodeOptions::Chain>(7)); },
       StatusCode::INVALID_ARGUMENT, "decode.chain: 7"},
      {"undefined method",
       [](auto& r) { r.mutable_decode()->set_method(static_cast<v1::DecodeOptions::Method>(-3)); },
       StatusCode::INVALID_ARGUMENT, "decode.method: -3"},
      {"undefined plane model",
       [](auto& r) {
         r.mutable_surface()->set_plane_model(static_cast<v1::SurfaceOptions::PlaneModel>(99));
       },
       StatusCode::INVALID_ARGUMENT, "surface.plane_model: 99"},
      {"undefined strips",
       [](auto& r) {
         r.mutable_surface()->set_strips(static_cast<v1::SurfaceOptions::StripMethod>(5));
       },
       StatusCode::INVALID_ARGUMENT, "surface.strips: 5"},
  };
  for (const Case& c : cases) {
    v1::ProcessFrameRequest request = FaceRequest(pattern::Side::kLeft, true);
    c.damage(request);
    const grpc::Status status = CallFrame(s, request);
    EXPECT_EQ(status.error_code(), c.code) << c.name << ": " << status.error_message();
    EXPECT_NE(status.error_message().find(c.says), std::string::npos)
        << c.name << ": " << status.error_message();
  }
  // Sessions: swapped calibrations, a distance with three points.
  v1::ReconstructSessionRequest swapped = SessionRequest();
  std::swap(*swapped.mutable_left_calibration(), *swapped.mutable_right_calibration());
  EXPECT_EQ(CallFrame(s, swapped).error_code(), StatusCode::INVALID_ARGUMENT);
  v1::ReconstructSessionRequest bad_distance = SessionRequest();
  for (int i = 0; i < 3; ++i) bad_distance.mutable_measurements()->add_distances()->add_points();
  const grpc::Status status = CallFrame(s, bad_distance);
  EXPECT_EQ(status.error_code(), StatusCode::INVALID_ARGUMENT);
  EXPECT_NE(status.error_message().find("distances[0]"), std::string::npos);
  v1::ReconstructSessionRequest bad_join = SessionRequest();
  bad_join.set_join(static_cast<v1::ReconstructSessionRequest::Join>(12));
  EXPECT_EQ(CallFrame(s, bad_join).error_code(), StatusCode::INVALID_ARGUMENT);
  v1::ReconstructSessionRequest bad_reference = SessionRequest();
  bad_reference.mutable_measurements()->set_reference(
      static_cast<v1::MeasurementPlan::Reference>(8));
  const grpc::Status reference = CallFrame(s, bad_reference);
  EXPECT_EQ(reference.error_code(), StatusCode::INVALID_ARGUMENT);
  EXPECT_NE(reference.error_message().find("measurements.reference: 8"), std::string::npos)
      << reference.error_message();
  // Nothing was left running or queued.
  EXPECT_EQ(s.service().Stats().busy + s.service().Stats().waiting, 0);
}

TEST(ProcessingService, CalibrationsAreCachedByContentHash) {
  InProcessService s;
  ProcessingClient client = s.Client();
  v1::CalibrationInfo info;
  ASSERT_TRUE(client.PutCalibration(CalibrationYaml(pattern::Side::kRight), &info).ok());
  EXPECT_EQ(info.id(), CalibrationCache::IdOf(CalibrationYaml(pattern::Side::kRight)));
  EXPECT_EQ(info.side(), v1::SIDE_RIGHT);
  EXPECT_TRUE(info.has_projector_matrix());
  v1::GetCalibrationRequest get;
  get.set_id(info.id());
  v1::CalibrationFile file;
  grpc::ClientContext context;
  ASSERT_TRUE(s.stub().GetCalibration(&context, get, &file).ok());
  EXPECT_EQ(file.yaml(), CalibrationYaml(pattern::Side::kRight));
  // By id from now on.
  v1::ProcessFrameRequest request = FaceRequest(pattern::Side::kRight, true);
  request.mutable_calibration()->set_id(info.id());
  const WorkOutcome out = client.ProcessFrame(request);
  ASSERT_TRUE(out.status.ok()) << out.status.error_message();
  EXPECT_TRUE(out.result.sides(0).q_absolute());
  // Unknown ids and files that are not calibrations.
  grpc::ClientContext c2;
  get.set_id("sha256:0");
  EXPECT_EQ(s.stub().GetCalibration(&c2, get, &file).error_code(), StatusCode::NOT_FOUND);
  EXPECT_EQ(client.PutCalibration("not: a calibration", &info).error_code(),
            StatusCode::INVALID_ARGUMENT);
  EXPECT_EQ(client.PutCalibration(std::string(5 << 20, 'x'), &info).error_code(),
            StatusCode::INVALID_ARGUMENT);
}

TEST(CalibrationCache, KeepsTheMostRecentlyUsed) {
  CalibrationCache cache(1);
  const auto left = cache.Put(CalibrationYaml(pattern::Side::kLeft), "left");
  EXPECT_EQ(cache.Find(left->id), left);
  const auto right = cache.Put(CalibrationYaml(pattern::Side::kRight), "right");
  EXPECT_EQ(cache.size(), 1u);
  EXPECT_EQ(cache.Find(left->id), nullptr);
  EXPECT_EQ(cache.Find(right->id), right);
  // An evicted entry stays valid for whoever holds it.
  EXPECT_EQ(left->calibration.side, pattern::Side::kLeft);
}

// Opens a Calibrate call and sends only its manifest: the call then holds a
// place in the pool until the stream is closed (Close). Events are read on a
// thread of their own, as a real client does.
struct HeldUpload {
  grpc::ClientContext context;
  std::unique_ptr<grpc::ClientReaderWriter<v1::CalibrateRequest, v1::WorkEvent>> stream;
  std::thread reader;

  explicit HeldUpload(InProcessService& s) {
    stream = s.stub().Calibrate(&context);
    v1::CalibrateRequest manifest;
    manifest.mutable_manifest()->set_yaml("side: left\n");
    EXPECT_TRUE(stream->Write(manifest));
    v1::WorkEvent queued;
    EXPECT_TRUE(stream->Read(&queued));  // admitted
    EXPECT_EQ(queued.progress().stage(), "queued");
    reader = std::thread([this] {
      v1::WorkEvent event;
      while (stream->Read(&event)) {
      }
    });
  }
  // Cancels the call and waits for its end.
  void Close() {
    context.TryCancel();
    reader.join();
    stream->Finish();
  }
};

TEST(ProcessingService, AFullPoolRefusesAtOnce) {
  ProcessingServiceOptions options;
  options.workers = 1;
  options.queue = 0;
  InProcessService s(options);
  {
    HeldUpload held(s);
    const auto start = std::chrono::steady_clock::now();
    const grpc::Status status = CallFrame(s, FaceRequest(pattern::Side::kLeft, false));
    EXPECT_EQ(status.error_code(), StatusCode::RESOURCE_EXHAUSTED) << status.error_message();
    EXPECT_LT(std::chrono::steady_clock::now() - start, std::chrono::seconds(2));
    EXPECT_EQ(s.service().Stats().rejected, 1u);
    held.Close();
  }
  // The place is free again.
  // The server sees the cancellation on its own thread: wait until the
  // held place (queued or holding the worker) has been given back.
  for (int i = 0; i < 250; ++i) {
    const auto stats = s.service().Stats();
    if (stats.waiting == 0 && stats.busy == 0) break;
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  EXPECT_TRUE(s.Client().ProcessFrame(FaceRequest(pattern::Side::kLeft, false)).status.ok());
}

// A ProcessFrame call read on gRPC's callback client: no thread of the
// test's waits for it.
class FrameCall final : public grpc::ClientReadReactor<v1::WorkEvent> {
 public:
  FrameCall(InProcessService& s, const v1::ProcessFrameRequest& request) : request_(request) {
    s.stub().async()->ProcessFrame(&context_, &request_, this);
    StartRead(&event_);
    StartCall();
  }
  void OnReadDone(bool ok) override {
    if (ok) StartRead(&event_);
  }
  void OnDone(const grpc::Status& status) override { done_.set_value(status); }
  // The call's status once it ended.
  grpc::Status Wait() { return ended_.get(); }

 private:
  grpc::ClientContext context_;
  v1::ProcessFrameRequest request_;
  v1::WorkEvent event_;
  std::promise<grpc::Status> done_;
  std::future<grpc::Status> ended_ = done_.get_future();
};

// Threads of this process now.
int ThreadCount() {
  return static_cast<int>(
      std::distance(fs::directory_iterator("/proc/self/task"), fs::directory_iterator()));
}

// The work calls are on the callback API and run on the pool's own
// workers: calls waiting for a worker hold no thread (on the synchronous
// API each held a handler thread until it got one).
TEST(ProcessingService, CallsWaitingForAWorkerHoldNoThread) {
  ProcessingServiceOptions options;
  options.workers = 1;
  options.queue = 12;
  InProcessService s(options);
  ASSERT_TRUE(s.Client().ProcessFrame(FaceRequest(pattern::Side::kLeft, false)).status.ok());
  const int before = ThreadCount();
  v1::ProcessFrameRequest slow;
  *slow.mutable_frame() = FrameMessage(testing::HostileFrame());
  slow.set_side(v1::SIDE_LEFT);
  std::vector<std::unique_ptr<FrameCall>> calls;
  calls.push_back(std::make_unique<FrameCall>(s, slow));  // holds the one worker a while
  for (int i = 0; i < 500 && s.service().Stats().busy == 0; ++i)
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  for (int i = 0; i < 12; ++i)
    calls.push_back(std::make_unique<FrameCall>(s, FaceRequest(pattern::Side::kLeft, false)));
  WorkPoolStats stats;
  for (int i = 0; i < 500; ++i) {
    stats = s.service().Stats();
    if (stats.busy == 1 && stats.waiting == 12) break;
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
  const int during = ThreadCount();
  EXPECT_EQ(stats.waiting, 12);
  EXPECT_LE(during - before, 3) << before << " threads before, " << during << " with 12 waiting";
  EXPECT_EQ(calls.front()->Wait().error_code(), StatusCode::FAILED_PRECONDITION);  // no pattern
  for (std::size_t i = 1; i < calls.size(); ++i) EXPECT_TRUE(calls[i]->Wait().ok()) << i;
}

TEST(ProcessingService, ACallPastItsDeadlineStops) {
  InProcessService s;
  grpc::ClientContext context;
  context.set_deadline(std::chrono::system_clock::now() + std::chrono::milliseconds(5));
  auto reader = s.stub().ReconstructSession(&context, SessionRequest());
  v1::WorkEvent event;
  bool got_result = false;
  while (reader->Read(&event)) got_result = got_result || event.has_result();
  const grpc::Status status = reader->Finish();
  EXPECT_EQ(status.error_code(), StatusCode::DEADLINE_EXCEEDED);
  EXPECT_FALSE(got_result);
  // The handler ends soon after: no worker stays busy.
  for (int i = 0; i < 200 && s.service().Stats().busy != 0; ++i)
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  EXPECT_EQ(s.service().Stats().busy, 0);
}

// Both chains: the track chain asks inside its tracks, line 0 and links;
// the skeleton chain between thinning iterations, graph builds and repair
// rounds.
class DeadlineInsideTheDecode : public ::testing::TestWithParam<v1::DecodeOptions::Chain> {};

TEST_P(DeadlineInsideTheDecode, FreesTheWorker) {
  InProcessService s;
  v1::ProcessFrameRequest request;
  *request.mutable_frame() = FrameMessage(testing::HostileFrame());
  request.set_side(v1::SIDE_LEFT);
  request.mutable_decode()->set_chain(GetParam());
  // How long the whole decode takes here (no deadline).
  auto start = std::chrono::steady_clock::now();
  (void)s.Client().ProcessFrame(request);
  const auto whole = std::chrono::steady_clock::now() - start;

  const auto allowed = whole / 5;
  grpc::ClientContext context;
  start = std::chrono::steady_clock::now();
  context.set_deadline(std::chrono::system_clock::now() + allowed);
  auto reader = s.stub().ProcessFrame(&context, request);
  v1::WorkEvent event;
  while (reader->Read(&event)) {
  }
  EXPECT_EQ(reader->Finish().error_code(), StatusCode::DEADLINE_EXCEEDED);
  // The worker comes free well before the decode would have ended: the
  // stages ask between themselves and inside the long ones.
  while (s.service().Stats().busy != 0 && std::chrono::steady_clock::now() - start < whole * 2)
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  const auto freed = std::chrono::steady_clock::now() - start;
  RecordProperty("decode_ms",
                 std::to_string(std::chrono::duration<double, std::milli>(whole).count()));
  RecordProperty(
      "freed_after_deadline_ms",
      std::to_string(std::chrono::duration<double, std::milli>(freed - allowed).count()));
  EXPECT_EQ(s.service().Stats().busy, 0);
  // Before the stripe mask and the skeleton chain's stages asked inside,
  // the skeleton chain's worker came free 210 ms after a 172 ms deadline on
  // an 860 ms decode (past this bound); now 20-60 ms after it.
  EXPECT_LT(freed, allowed + (whole - allowed) / 4)
      << "decode " << std::chrono::duration<double>(whole).count() << " s, deadline "
      << std::chrono::duration<double>(allowed).count() << " s, worker free after "
      << std::chrono::duration<double>(freed).count() << " s";
}

INSTANTIATE_TEST_SUITE_P(ProcessingService, DeadlineInsideTheDecode,
                         ::testing::Values(v1::DecodeOptions::CHAIN_TRACKS,
                                           v1::DecodeOptions::CHAIN_SKELETON),
                         [](const auto& chain) {
                           return chain.param == v1::DecodeOptions::CHAIN_TRACKS ? "Tracks"
                                                                                 : "Skeleton";
                         });

TEST(ProcessingService, AFrameAboveThePixelBudgetIsRefusedBeforeAnyWork) {
  ProcessingServiceOptions options;
  options.max_frame_pixels = 512 * 512;
  InProcessService s(options);
  EXPECT_TRUE(s.Client().ProcessFrame(FaceRequest(pattern::Side::kLeft, false)).status.ok());
  v1::ProcessFrameRequest request;
  *request.mutable_frame() = FrameMessage(cv::Mat(512, 513, CV_8UC1, cv::Scalar(9)));
  request.set_side(v1::SIDE_LEFT);
  const grpc::Status status = s.Client().ProcessFrame(request).status;
  EXPECT_EQ(status.error_code(), StatusCode::INVALID_ARGUMENT);
  EXPECT_NE(status.error_message().find("max_frame_pixels"), std::string::npos)
      << status.error_message();
  EXPECT_NE(status.error_message().find("frame: 513 x 512"), std::string::npos)
      << status.error_message();
}

// The files of a rendered calibration session, relative to its folder.
std::vector<UploadFile> SessionFiles(const fs::path& folder, std::string* manifest) {
  std::vector<UploadFile> files;
  for (const auto& entry : fs::recursive_directory_iterator(folder)) {
    if (!entry.is_regular_file()) continue;
    std::ifstream in(entry.path(), std::ios::binary);
    std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    const std::string rel = fs::relative(entry.path(), folder).string();
    if (rel == simulator::kSessionManifestName)
      *manifest = bytes;
    else if (entry.path().extension() == ".png")
      files.push_back({rel, std::move(bytes)});
  }
  return files;
}

bool ScratchIsEmpty(const fs::path& scratch) { return fs::is_empty(scratch); }

TEST(ProcessingService, CalibrateFromAnUploadedSession) {
  const fs::path scratch = fs::path(::testing::TempDir()) / ("scratch-" + std::to_string(getpid()));
  fs::create_directories(scratch);
  ProcessingServiceOptions options;
  options.scratch_dir = scratch;
  InProcessService s(options);
  std::string manifest;
  const std::vector<UploadFile> files =
      SessionFiles(calibration::testing::SessionFolder(SessionKind::kRightClean), &manifest);
  ASSERT_FALSE(files.empty());
  int views = 0;
  const WorkOutcome out = s.Client().Calibrate(
      manifest, files, "rig 2",
      [&](const v1::Progress& p) { views += p.stage().starts_with("calibrate "); });
  ASSERT_TRUE(out.status.ok()) << out.status.error_message();
  EXPECT_EQ(views, static_cast<int>(files.size()));
  ASSERT_TRUE(out.files.count("calibration.yaml"));
  EXPECT_EQ(out.result.calibration_id(), CalibrationCache::IdOf(out.files.at("calibration.yaml")));
  EXPECT_NE(s.service().calibrations().Find(out.result.calibration_id()), nullptr);
  const calibration::CalibrationRecord record =
      calibration::CalibrationFromYaml(out.files.at("calibration.yaml"), "uploaded");
  EXPECT_EQ(record.calibration.side, pattern::Side::kRight);
  EXPECT_TRUE(out.files.count("calibration-report.json"));
  EXPECT_TRUE(ScratchIsEmpty(scratch));
  // The same upload gives the same file, so the same id (no scratch paths inside).
  EXPECT_EQ(out.files.at("calibration.yaml").find(scratch.string()), std::string::npos);
  const WorkOutcome again = s.Client().Calibrate(manifest, files);
  ASSERT_TRUE(again.status.ok()) << again.status.error_message();
  EXPECT_EQ(again.result.calibration_id(), out.result.calibration_id());

  // A manifest naming files outside the upload is refused, whether they exist or not.
  std::string outside = manifest;
  const std::string first_image = files[0].path;
  outside.replace(outside.find(first_image), first_image.size(), "/etc/passwd");
  WorkOutcome escaped = s.Client().Calibrate(outside, files);
  EXPECT_EQ(escaped.status.error_code(), StatusCode::INVALID_ARGUMENT);
  EXPECT_NE(escaped.status.error_message().find("not one of the uploaded files"), std::string::npos)
      << escaped.status.error_message();

  // A missing image is named as the client knows it; nothing is left behind.
  std::vector<UploadFile> missing(files.begin() + 1, files.end());
  WorkOutcome bad = s.Client().Calibrate(manifest, missing);
  EXPECT_EQ(bad.status.error_code(), StatusCode::INVALID_ARGUMENT);
  EXPECT_NE(bad.status.error_message().find(files[0].path), std::string::npos)
      << bad.status.error_message();
  EXPECT_EQ(bad.status.error_message().find(scratch.string()), std::string::npos);
  // Paths that leave the folder, and no manifest at all.
  std::vector<UploadFile> escaping = files;
  escaping[0].path = "../" + escaping[0].path;
  bad = s.Client().Calibrate(manifest, escaping);
  EXPECT_EQ(bad.status.error_code(), StatusCode::INVALID_ARGUMENT);
  EXPECT_NE(bad.status.error_message().find(".."), std::string::npos);
  escaping[0].path = "/etc/passwd";
  EXPECT_EQ(s.Client().Calibrate(manifest, escaping).status.error_code(),
            StatusCode::INVALID_ARGUMENT);
  grpc::ClientContext context;
  auto stream = s.stub().Calibrate(&context);
  stream->WritesDone();
  v1::WorkEvent event;
  while (stream->Read(&event)) {
  }
  EXPECT_EQ(stream->Finish().error_code(), StatusCode::INVALID_ARGUMENT);
  // A client that gives up in the middle of its upload.
  {
    HeldUpload held(s);
    v1::CalibrateRequest part;
    part.mutable_file()->set_path("a.png");
    part.mutable_file()->set_data("1234");
    held.stream->Write(part);
    held.Close();
  }
  for (int i = 0; i < 100 && !ScratchIsEmpty(scratch); ++i)
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  EXPECT_TRUE(ScratchIsEmpty(scratch));
  fs::remove_all(scratch);
}

// A screen view that does not decode is dropped and named in the report, as
// the client named it; two of them leave too few, and the refusal names them.
TEST(ProcessingService, CalibrateDropsAViewThatGivesNothing) {
  const fs::path scratch =
      fs::path(::testing::TempDir()) / ("scratch-drop-" + std::to_string(getpid()));
  fs::create_directories(scratch);
  ProcessingServiceOptions options;
  options.scratch_dir = scratch;
  InProcessService s(options);
  std::string manifest;
  std::vector<UploadFile> files =
      SessionFiles(calibration::testing::SessionFolder(SessionKind::kRightClean), &manifest);
  auto bytes_of = [&files](const std::string& path) -> std::string& {
    for (UploadFile& f : files)
      if (f.path == path) return f.bytes;
    throw std::logic_error("the session has no " + path);
  };
  // The target where the 40 mm screen should be: nothing to decode.
  bytes_of("screen_z040.png") = bytes_of("target_z000.png");
  WorkOutcome out = s.Client().Calibrate(manifest, files);
  ASSERT_TRUE(out.status.ok()) << out.status.error_message();
  const nlohmann::json report = nlohmann::json::parse(out.files.at("calibration-report.json"));
  ASSERT_EQ(report.at("dropped_views").size(), 1u) << report.at("dropped_views").dump();
  EXPECT_EQ(report.at("dropped_views")[0].at("image"), "screen_z040.png");
  EXPECT_EQ(report.at("dropped_views")[0].at("kind"), "screen");
  EXPECT_EQ(report.at("screens").size(), 3u);
  const std::string& yaml = out.files.at("calibration.yaml");
  EXPECT_NE(yaml.find("dropped_views:"), std::string::npos);
  EXPECT_EQ(yaml.find(scratch.string()), std::string::npos);

  bytes_of("screen_z080.png") = bytes_of("target_z000.png");
  out = s.Client().Calibrate(manifest, files);
  EXPECT_EQ(out.status.error_code(), StatusCode::FAILED_PRECONDITION);
  const std::string& message = out.status.error_message();
  EXPECT_NE(message.find("2 of 4 screen views usable"), std::string::npos) << message;
  EXPECT_NE(message.find("screen_z040.png (screen view 2, z = 40 mm): the brick pattern"),
            std::string::npos)
      << message;
  EXPECT_NE(message.find("screen_z080.png (screen view 3"), std::string::npos) << message;
  EXPECT_EQ(message.find(scratch.string()), std::string::npos) << message;
  EXPECT_TRUE(ScratchIsEmpty(scratch));
  fs::remove_all(scratch);
}

// A message inside the Calibrate upload that is not a CalibrateRequest is
// refused with INVALID_ARGUMENT naming the message, wherever it comes: gRPC's
// typed reader took it for the upload's end, so the files sent before it
// were calibrated as if they were the whole upload (or the first message
// read as "no manifest").
TEST(ProcessingService, AMalformedMessageInTheCalibrateUploadIsRefusedByNumber) {
  const fs::path scratch =
      fs::path(::testing::TempDir()) / ("scratch-malformed-" + std::to_string(getpid()));
  fs::create_directories(scratch);
  ProcessingServiceOptions options;
  options.scratch_dir = scratch;
  options.software_version = "test";
  // On a Unix socket, not the in-process channel: there a reply is sent only
  // once the other side reads, and the raw client reads after its upload.
  ProcessingService service(options);
  const std::string socket =
      (scratch.parent_path() / ("malformed-" + std::to_string(getpid()))).string() + ".sock";
  grpc::ServerBuilder builder;
  builder.SetMaxReceiveMessageSize(40 << 20);
  builder.AddListeningPort("unix:" + socket, grpc::InsecureServerCredentials());
  builder.RegisterService(&service);
  const std::unique_ptr<grpc::Server> server = builder.BuildAndStart();
  ASSERT_NE(server, nullptr);
  std::string manifest;
  const std::vector<UploadFile> files =
      SessionFiles(calibration::testing::SessionFolder(SessionKind::kRightClean), &manifest);
  ASSERT_FALSE(files.empty());
  const auto serialized = [](const v1::CalibrateRequest& part) {
    std::string bytes;
    EXPECT_TRUE(part.SerializeToString(&bytes));
    return bytes;
  };
  v1::CalibrateRequest manifest_part;
  manifest_part.mutable_manifest()->set_yaml(manifest);
  // Every file of the session, whole, each in one message.
  std::vector<std::string> upload = {serialized(manifest_part)};
  for (const UploadFile& f : files) {
    v1::CalibrateRequest part;
    part.mutable_file()->set_path(f.path);
    part.mutable_file()->set_data(f.bytes);
    part.mutable_file()->set_last(true);
    upload.push_back(serialized(part));
  }
  const std::string not_a_message(kNotAMessage, sizeof kNotAMessage - 1);
  grpc::ChannelArguments args;
  args.SetMaxSendMessageSize(40 << 20);
  grpc::GenericStub stub(
      grpc::CreateCustomChannel("unix:" + socket, grpc::InsecureChannelCredentials(), args));
  // First, after the manifest, and between files (the upload complete but
  // for the file after it) and after the last file.
  for (std::size_t at : {std::size_t{0}, std::size_t{1}, upload.size() - 1, upload.size()}) {
    RawCall call;
    call.method = "/bsls.v1.Processing/Calibrate";
    call.messages.assign(upload.begin(), upload.begin() + static_cast<std::ptrdiff_t>(at));
    call.messages.push_back(not_a_message);
    call.messages.insert(call.messages.end(), upload.begin() + static_cast<std::ptrdiff_t>(at),
                         upload.end());
    call.deadline_ms = 60000;
    const RawOutcome outcome = SendRaw(stub, call);
    EXPECT_EQ(outcome.code, StatusCode::INVALID_ARGUMENT) << "at " << at << ": " << outcome.message;
    EXPECT_NE(outcome.message.find("message " + std::to_string(at + 1) +
                                   " of the upload (6 bytes) "
                                   "is not a bsls.v1.CalibrateRequest message"),
              std::string::npos)
        << "at " << at << ": " << outcome.message;
  }
  EXPECT_TRUE(ScratchIsEmpty(scratch));
  // The same upload without the bad message calibrates.
  RawCall whole;
  whole.method = "/bsls.v1.Processing/Calibrate";
  whole.messages = upload;
  whole.deadline_ms = 60000;
  const RawOutcome outcome = SendRaw(stub, whole);
  EXPECT_EQ(outcome.code, StatusCode::OK) << outcome.message;
  EXPECT_EQ(service.Stats().busy, 0);
  service.BeginDrain();
  server->Shutdown(std::chrono::system_clock::now() + std::chrono::seconds(5));
  fs::remove_all(scratch);
}

TEST(ProcessingService, DrainingRefusesNewWork) {
  InProcessService s;
  s.service().BeginDrain();
  EXPECT_EQ(CallFrame(s, FaceRequest(pattern::Side::kLeft, false)).error_code(),
            StatusCode::UNAVAILABLE);
}

}  // namespace
}  // namespace bsls::processing::test
