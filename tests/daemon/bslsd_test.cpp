// bslsd as its users meet it: the real executable started on a temporary
// socket and store, driven over gRPC.
#include <grp.h>
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <sys/wait.h>

#include <algorithm>
#include <atomic>
#include <cstdio>
#include <map>
#include <random>
#include <set>
#include <sstream>
#include <utility>
#include <vector>

#include "bsls/common/sha256.h"
#include "bsls/testing/build_paths.h"
#include "bsls/testing/certificates.h"
#include "bsls/testing/raw_connections.h"
#include "daemon_process.h"
#include "raw_calls.h"

namespace bsls::testing {
namespace {

using std::chrono::milliseconds;
using std::chrono::seconds;

constexpr const char* kSimulatedSlides = "slides:\n  backend: simulated\n";

// Bytes that are no message of any type: field 1, length-delimited, with a
// length of 4 GiB that does not follow.

// SHA-256 of a frame's packed pixels (what the store hashes).
std::string PixelHash(const v1::Frame& frame) {
  std::string packed;
  for (std::uint32_t y = 0; y < frame.height(); ++y)
    packed.append(frame.pixels(), static_cast<std::size_t>(y) * frame.stride(), frame.width());
  return Sha256Hex(packed);
}

v1::GrabResponse GrabBoth(v1::CaptureDaemon::Stub& stub, const std::string& session,
                          grpc::Status* status, bool frames = false) {
  v1::GrabRequest request;
  request.set_side(v1::GRAB_SIDE_BOTH);
  request.set_session_id(session);
  request.set_patient_reference("P-0001");
  request.set_include_frames(frames);
  v1::GrabResponse reply;
  *status = stub.Grab(Deadline(milliseconds(30000)).get(), request, &reply);
  return reply;
}

class Bslsd : public ::testing::Test {
 protected:
  // A daemon on simulated devices; `extra` is more configuration (YAML), with
  // its own roles: section or else root as admin.
  void Start(const std::string& name, const std::string& extra = kSimulatedSlides,
             std::vector<std::string> args = {}) {
    dir_ = MakeDaemonDir(name);
    const bool has_roles = extra.find("roles:") != std::string::npos;
    config_ = WriteDaemonConfig(dir_, (has_roles ? "" : "roles:\n  admin: [root]\n") + extra);
    daemon_ = std::make_unique<DaemonProcess>(dir_, config_, std::move(args));
    ASSERT_TRUE(daemon_->ready()) << daemon_->Log();
  }
  void TearDown() override {
    if (daemon_ && !daemon_->exited()) {
      EXPECT_EQ(daemon_->Terminate(), 0) << daemon_->Log();
    }
  }
  fs::path dir_;
  fs::path config_;
  std::unique_ptr<DaemonProcess> daemon_;
};

TEST_F(Bslsd, GrabsBothSidesAndKeepsThemWithTheirMetadata) {
  Start("grab");
  auto stub = daemon_->Stub();
  v1::DeviceStatus status;
  ASSERT_TRUE(stub->GetStatus(Deadline(milliseconds(5000)).get(), {}, &status).ok());
  EXPECT_EQ(status.backend(), "simulated");
  EXPECT_EQ(status.caller_role(), "admin");
  EXPECT_EQ(status.cameras_size(), 2);
  EXPECT_EQ(status.width(), 512u);

  grpc::Status grab_status;
  const v1::GrabResponse grab = GrabBoth(*stub, "session-1", &grab_status, true);
  ASSERT_TRUE(grab_status.ok()) << grab_status.error_message();
  const v1::CaptureInfo& info = grab.capture();
  EXPECT_EQ(info.capture_id().size(), 32u);
  EXPECT_EQ(info.side(), v1::GRAB_SIDE_BOTH);
  EXPECT_EQ(info.session_id(), "session-1");
  EXPECT_EQ(info.patient_reference(), "P-0001");
  EXPECT_EQ(info.requested_by(), "root");
  ASSERT_EQ(info.frames_size(), 2);
  EXPECT_EQ(info.frames(0).camera(), v1::CAMERA_LEFT);
  EXPECT_EQ(info.frames(1).camera(), v1::CAMERA_RIGHT);
  for (const v1::Frame& frame : info.frames()) {
    EXPECT_EQ(frame.pixels().size(), static_cast<std::size_t>(frame.stride()) * frame.height());
    EXPECT_EQ(PixelHash(frame), frame.sha256());
    EXPECT_LE(frame.requested_monotonic_ns(), frame.delivered_monotonic_ns());
  }

  v1::GetCaptureRequest get;
  get.set_capture_id(info.capture_id());
  v1::CaptureInfo stored;
  ASSERT_TRUE(stub->GetCapture(Deadline(milliseconds(5000)).get(), get, &stored).ok());
  ASSERT_EQ(stored.frames_size(), 2);
  for (int i = 0; i < 2; ++i) {
    EXPECT_EQ(PixelHash(stored.frames(i)), info.frames(i).sha256());
    EXPECT_EQ(stored.frames(i).pixels(), info.frames(i).pixels());
  }
  v1::ListCapturesRequest list;
  list.set_session_id("session-1");
  v1::ListCapturesResponse listed;
  ASSERT_TRUE(stub->ListCaptures(Deadline(milliseconds(5000)).get(), list, &listed).ok());
  ASSERT_EQ(listed.captures_size(), 1);
  EXPECT_EQ(listed.captures(0).capture_id(), info.capture_id());
  EXPECT_TRUE(listed.captures(0).frames(0).pixels().empty());  // metadata only

  // The capture outlives the daemon.
  ASSERT_EQ(daemon_->Terminate(), 0) << daemon_->Log();
  daemon_ = std::make_unique<DaemonProcess>(dir_, config_);
  ASSERT_TRUE(daemon_->ready()) << daemon_->Log();
  stub = daemon_->Stub();
  v1::CaptureInfo again;
  ASSERT_TRUE(stub->GetCapture(Deadline(milliseconds(5000)).get(), get, &again).ok());
  EXPECT_EQ(again.frames(0).sha256(), info.frames(0).sha256());
}

TEST_F(Bslsd, BadInputGetsTheRightStatusAndTheDaemonKeepsServing) {
  Start("bad_input");
  auto stub = daemon_->Stub();
  auto expect = [](const grpc::Status& status, grpc::StatusCode code, const std::string& words) {
    EXPECT_EQ(status.error_code(), code) << status.error_message();
    EXPECT_NE(status.error_message().find(words), std::string::npos) << status.error_message();
  };
  v1::DeviceStatus device;
  {
    v1::SelectCameraRequest request;
    request.set_camera(static_cast<v1::Camera>(9));
    expect(stub->SelectCamera(Deadline(milliseconds(5000)).get(), request, &device),
           grpc::StatusCode::INVALID_ARGUMENT, "camera 9");
    request.set_camera(v1::CAMERA_THIRD);  // a camera the simulated rig does not have
    expect(stub->SelectCamera(Deadline(milliseconds(5000)).get(), request, &device),
           grpc::StatusCode::INVALID_ARGUMENT, "third");
  }
  {
    v1::SetGainRequest request;
    request.set_gain(4000);
    expect(stub->SetGain(Deadline(milliseconds(5000)).get(), request, &device),
           grpc::StatusCode::INVALID_ARGUMENT, "gain 4000");
  }
  {
    v1::GetCaptureRequest request;
    request.set_capture_id(std::string(32, 'a'));
    v1::CaptureInfo info;
    expect(stub->GetCapture(Deadline(milliseconds(5000)).get(), request, &info),
           grpc::StatusCode::NOT_FOUND, std::string(32, 'a'));
    request.set_capture_id("../../etc/passwd");
    expect(stub->GetCapture(Deadline(milliseconds(5000)).get(), request, &info),
           grpc::StatusCode::INVALID_ARGUMENT, "capture id");
    v1::DeleteCaptureRequest del;
    del.set_capture_id(std::string(32, 'b'));
    v1::DeleteCaptureResponse deleted;
    expect(stub->DeleteCapture(Deadline(milliseconds(5000)).get(), del, &deleted),
           grpc::StatusCode::NOT_FOUND, std::string(32, 'b'));
  }
  {
    v1::GrabRequest request;
    request.set_side(v1::GRAB_SIDE_UNSPECIFIED);
    v1::GrabResponse reply;
    expect(stub->Grab(Deadline(milliseconds(5000)).get(), request, &reply),
           grpc::StatusCode::INVALID_ARGUMENT, "grab side");
    request.set_side(v1::GRAB_SIDE_LEFT);
    request.set_session_id(std::string(300, 's'));
    expect(stub->Grab(Deadline(milliseconds(5000)).get(), request, &reply),
           grpc::StatusCode::INVALID_ARGUMENT, "session_id");
    // Beyond the daemon's receive cap (64 KiB): refused before any handler runs.
    request.set_session_id(std::string(200000, 's'));
    EXPECT_EQ(stub->Grab(Deadline(milliseconds(5000)).get(), request, &reply).error_code(),
              grpc::StatusCode::RESOURCE_EXHAUSTED);
  }
  {
    v1::SetSlideRequest request;
    request.set_slide(7);
    v1::SlideState state;
    expect(stub->SetSlide(Deadline(milliseconds(5000)).get(), request, &state),
           grpc::StatusCode::INVALID_ARGUMENT, "slide 7");
    v1::SetFocusRequest focus;
    focus.set_steps(5000);
    expect(stub->SetFocus(Deadline(milliseconds(5000)).get(), focus, &state),
           grpc::StatusCode::INVALID_ARGUMENT, "focus steps 5000");
  }
  {
    v1::ListCapturesRequest request;
    request.set_page_size(5000);
    v1::ListCapturesResponse reply;
    expect(stub->ListCaptures(Deadline(milliseconds(5000)).get(), request, &reply),
           grpc::StatusCode::INVALID_ARGUMENT, "page_size");
    request.set_page_size(10);
    request.set_page_token("not a token");
    EXPECT_EQ(stub->ListCaptures(Deadline(milliseconds(5000)).get(), request, &reply).error_code(),
              grpc::StatusCode::INVALID_ARGUMENT);
  }
  {
    // A client that opens a preview and vanishes without reading.
    auto context = Deadline(milliseconds(20000));
    auto reader = stub->StreamPreview(context.get(), {});
    context->TryCancel();
  }
  // Nothing of that hurt: status and grabs still work, nothing was stored.
  ASSERT_TRUE(stub->GetStatus(Deadline(milliseconds(5000)).get(), {}, &device).ok());
  EXPECT_EQ(device.captures_stored(), 0u);
  grpc::Status grab;
  GrabBoth(*stub, "after", &grab);
  EXPECT_TRUE(grab.ok()) << grab.error_message();
}

TEST_F(Bslsd, FullDiskFailsTheGrabClearlyAndStoresNothing) {
  // A reserve larger than any disk: every grab is refused before writing.
  Start("full_disk", std::string(kSimulatedSlides) + "limits:\n  max_preview_streams: 2\n",
        {"--set", "store.reserve_mib=1000000"});
  auto stub = daemon_->Stub();
  grpc::Status grab;
  GrabBoth(*stub, "full", &grab);
  EXPECT_EQ(grab.error_code(), grpc::StatusCode::RESOURCE_EXHAUSTED) << grab.error_message();
  EXPECT_NE(grab.error_message().find("nothing was written"), std::string::npos);
  v1::DeviceStatus device;
  ASSERT_TRUE(stub->GetStatus(Deadline(milliseconds(5000)).get(), {}, &device).ok());
  EXPECT_EQ(device.captures_stored(), 0u);
}

TEST_F(Bslsd, EveryCapabilityIsDroppedAndGrabsStillWork) {
  Start("caps");
  std::size_t threads = 0;
  for (const auto& task :
       fs::directory_iterator("/proc/" + std::to_string(daemon_->pid()) + "/task")) {
    std::ifstream in(task.path() / "status");
    std::map<std::string, std::string> caps;
    for (std::string line; std::getline(in, line);)
      if (line.rfind("Cap", 0) == 0)
        caps[line.substr(0, 6)] = line.substr(line.find_last_of(" \t") + 1);
    EXPECT_EQ(caps["CapEff"], "0000000000000000") << task.path();
    EXPECT_EQ(caps["CapPrm"], "0000000000000000") << task.path();
    EXPECT_EQ(caps["CapAmb"], "0000000000000000") << task.path();
    ++threads;
  }
  EXPECT_GT(threads, 1u);
  auto stub = daemon_->Stub();
  grpc::Status grab;
  GrabBoth(*stub, "caps", &grab);
  EXPECT_TRUE(grab.ok()) << grab.error_message();
}

TEST_F(Bslsd, SlidesChangeAndEveryWatcherHearsOfIt) {
  Start("slides");
  auto stub = daemon_->Stub();
  auto context = Deadline(milliseconds(30000));
  auto events = stub->WatchEvents(context.get(), {});
  events->WaitForInitialMetadata();
  v1::SetSlideRequest request;
  request.set_slide(1);
  v1::SlideState state;
  grpc::Status status = stub->SetSlide(Deadline(milliseconds(20000)).get(), request, &state);
  ASSERT_TRUE(status.ok()) << status.error_message();
  EXPECT_EQ(state.slide(), 1);
  EXPECT_TRUE(state.in_place());
  v1::SetLampRequest lamp;
  lamp.set_on(true);
  ASSERT_TRUE(stub->SetLamp(Deadline(milliseconds(5000)).get(), lamp, &state).ok());
  EXPECT_TRUE(state.lamp_on());
  grpc::Status grab;
  const v1::GrabResponse stored = GrabBoth(*stub, "slides", &grab);
  ASSERT_TRUE(grab.ok()) << grab.error_message();
  EXPECT_EQ(stored.capture().slide(), 1);

  bool saw_slide = false, saw_capture = false;
  v1::Event event;
  while ((!saw_slide || !saw_capture) && events->Read(&event)) {
    if (event.has_slide_changed() && event.slide_changed().slide() == 1 &&
        event.slide_changed().in_place())
      saw_slide = true;
    if (event.has_capture_stored() &&
        event.capture_stored().capture_id() == stored.capture().capture_id())
      saw_capture = true;
  }
  EXPECT_TRUE(saw_slide);
  EXPECT_TRUE(saw_capture);
  context->TryCancel();
}

TEST_F(Bslsd, SigtermDrainsTheGrabUnderWayAndLosesNothing) {
  Start("drain");
  auto stub = daemon_->Stub();
  std::atomic<bool> done{false};
  grpc::Status grab;
  v1::GrabResponse reply;
  std::thread caller([&] {
    reply = GrabBoth(*stub, "drain", &grab);
    done = true;
  });
  std::this_thread::sleep_for(milliseconds(20));
  EXPECT_EQ(daemon_->Terminate(), 0) << daemon_->Log();
  caller.join();
  // Either the grab made it (and must then be stored) or it was refused as
  // the daemon shut down; never acknowledged and lost. A refusal is the
  // service's UNAVAILABLE (draining) or, when the call reached the transport
  // as the server began to shut down, gRPC's own CANCELLED of a call no
  // handler took; nothing else.
  if (!grab.ok()) {
    EXPECT_TRUE(grab.error_code() == grpc::StatusCode::UNAVAILABLE ||
                grab.error_code() == grpc::StatusCode::CANCELLED)
        << grab.error_code() << " " << grab.error_message();
  }
  daemon_ = std::make_unique<DaemonProcess>(dir_, config_);
  ASSERT_TRUE(daemon_->ready()) << daemon_->Log();
  auto restarted = daemon_->Stub();
  v1::ListCapturesRequest list;
  v1::ListCapturesResponse listed;
  ASSERT_TRUE(restarted->ListCaptures(Deadline(milliseconds(5000)).get(), list, &listed).ok());
  if (grab.ok()) {
    v1::GetCaptureRequest get;
    get.set_capture_id(reply.capture().capture_id());
    v1::CaptureInfo stored;
    EXPECT_TRUE(restarted->GetCapture(Deadline(milliseconds(5000)).get(), get, &stored).ok());
    EXPECT_EQ(stored.frames_size(), 2);
  }
  // Whatever the store holds after the restart is whole: both frames of a grab.
  for (const v1::CaptureInfo& capture : listed.captures()) EXPECT_EQ(capture.frames_size(), 2);
}

TEST_F(Bslsd, SigkillDuring200GrabsLosesNoAcknowledgedCapture) {
  Start("sigkill");
  std::mt19937 random(20261122);
  std::vector<std::string> acknowledged;
  int attempts = 0;
  while (attempts < 200) {
    // Grab from two clients while the daemon is killed at a random moment.
    std::atomic<bool> stop{false};
    std::mutex mutex;
    // Each client grabs until its call fails (the daemon is gone).
    auto client = [&] {
      auto stub = daemon_->Stub();
      while (!stop) {
        {
          std::lock_guard lock(mutex);
          if (attempts >= 200) break;
          ++attempts;
        }
        v1::GrabRequest request;
        request.set_side(v1::GRAB_SIDE_LEFT);
        request.set_session_id("kill");
        v1::GrabResponse reply;
        const grpc::Status status =
            stub->Grab(Deadline(milliseconds(10000)).get(), request, &reply);
        if (!status.ok()) break;
        std::lock_guard lock(mutex);
        acknowledged.push_back(reply.capture().capture_id());
      }
    };
    std::thread a(client), b(client);
    std::this_thread::sleep_for(
        milliseconds(std::uniform_int_distribution<int>(1000, 4000)(random)));
    daemon_->Kill();
    stop = true;
    a.join();
    b.join();
    daemon_ = std::make_unique<DaemonProcess>(dir_, config_);
    ASSERT_TRUE(daemon_->ready()) << daemon_->Log();
  }
  ASSERT_GT(acknowledged.size(), 20u);
  auto stub = daemon_->Stub();
  for (const std::string& id : acknowledged) {
    v1::GetCaptureRequest get;
    get.set_capture_id(id);
    v1::CaptureInfo stored;
    const grpc::Status status = stub->GetCapture(Deadline(milliseconds(10000)).get(), get, &stored);
    ASSERT_TRUE(status.ok()) << id << ": " << status.error_message();
    ASSERT_EQ(stored.frames_size(), 1);
    EXPECT_EQ(PixelHash(stored.frames(0)), stored.frames(0).sha256()) << id;
  }
  std::printf(
      "[ figures  ] %zu of %d grabs acknowledged across the kills; all present and verified\n",
      acknowledged.size(), attempts);
}

TEST_F(Bslsd, EmulatedIsaCardBackendGrabsBothSides) {
  Start("isa", kSimulatedSlides, {"--backend", "emulated-isa"});
  auto stub = daemon_->Stub();
  v1::DeviceStatus status;
  ASSERT_TRUE(stub->GetStatus(Deadline(milliseconds(5000)).get(), {}, &status).ok());
  EXPECT_EQ(status.backend(), "isa");
  grpc::Status grab;
  const v1::GrabResponse reply = GrabBoth(*stub, "isa", &grab, true);
  ASSERT_TRUE(grab.ok()) << grab.error_message();
  ASSERT_EQ(reply.capture().frames_size(), 2);
  // The card's black level 64 extended back to 0..255 (thesis 3.11): a face
  // with stripes, not a flat picture.
  const std::string& pixels = reply.capture().frames(0).pixels();
  const auto [lo, hi] = std::minmax_element(pixels.begin(), pixels.end(), [](char a, char b) {
    return static_cast<unsigned char>(a) < static_cast<unsigned char>(b);
  });
  EXPECT_LT(static_cast<unsigned char>(*lo), 30);
  EXPECT_GT(static_cast<unsigned char>(*hi), 150);
}

TEST_F(Bslsd, EmulatedUsbFramestoreBackendGrabsBothSides) {
  Start("usb", kSimulatedSlides, {"--backend", "emulated-usb"});
  auto stub = daemon_->Stub();
  v1::DeviceStatus status;
  ASSERT_TRUE(stub->GetStatus(Deadline(milliseconds(5000)).get(), {}, &status).ok());
  EXPECT_EQ(status.backend(), "usb");
  grpc::Status grab;
  const v1::GrabResponse reply = GrabBoth(*stub, "usb", &grab, true);
  ASSERT_TRUE(grab.ok()) << grab.error_message();
  ASSERT_EQ(reply.capture().frames_size(), 2);
  EXPECT_EQ(PixelHash(reply.capture().frames(1)), reply.capture().frames(1).sha256());
}

// A stub over TCP with `client` as the client certificate (none when its
// key is empty), trusting `server_ca`.
std::unique_ptr<v1::CaptureDaemon::Stub> TlsStub(int port, const fs::path& server_ca,
                                                 const PemFiles& client) {
  grpc::SslCredentialsOptions tls;
  tls.pem_root_certs = ReadText(server_ca);
  if (!client.key.empty()) {
    tls.pem_private_key = ReadText(client.key);
    tls.pem_cert_chain = ReadText(client.certificate);
  }
  grpc::ChannelArguments args;
  args.SetInt(GRPC_ARG_USE_LOCAL_SUBCHANNEL_POOL, 1);  // a fresh handshake per stub
  return v1::CaptureDaemon::NewStub(grpc::CreateCustomChannel("127.0.0.1:" + std::to_string(port),
                                                              grpc::SslCredentials(tls), args));
}

// Remote callers: TCP is mutual TLS only, the certificate's common name is
// the caller and maps to a role; no certificate, or one from another CA,
// never gets past the handshake; the Unix socket keeps working beside it.
TEST_F(Bslsd, TcpServesOnlyMutualTlsCallersWithTheirCertificatesRole) {
  dir_ = MakeDaemonDir("tls");
  TestPki pki(dir_ / "pki", "clinic");
  const PemFiles server = pki.Issue("localhost", true);
  const PemFiles analyst = pki.Issue("analyst");
  const PemFiles station = pki.Issue("station");
  const PemFiles stranger = pki.Issue("stranger");
  TestPki rogue(dir_ / "pki", "rogue");
  const PemFiles forged = rogue.Issue("station");
  ASSERT_TRUE(pki.ok() && rogue.ok()) << "openssl could not make the test certificates";
  const int port = FreeLoopbackPort();
  ASSERT_GT(port, 0);
  config_ = WriteDaemonConfig(dir_, std::string(kSimulatedSlides) +
                                        "roles:\n  admin: [root]\n  certificates:\n"
                                        "    analyst: viewer\n    station: operator\n");
  daemon_ = std::make_unique<DaemonProcess>(
      dir_, config_,
      std::vector<std::string>{"--tcp", "127.0.0.1:" + std::to_string(port), "--set",
                               "listen.tls_certificate=" + server.certificate.string(), "--set",
                               "listen.tls_key=" + server.key.string(), "--set",
                               "listen.tls_client_ca=" + pki.ca().string()});
  ASSERT_TRUE(daemon_->ready()) << daemon_->Log();

  // The analyst (viewer) sees the status but may not grab.
  auto viewer = TlsStub(port, pki.ca(), analyst);
  v1::DeviceStatus status;
  grpc::Status call = viewer->GetStatus(Deadline(milliseconds(10000)).get(), {}, &status);
  ASSERT_TRUE(call.ok()) << call.error_message() << "\n" << daemon_->Log();
  EXPECT_EQ(status.caller_role(), "viewer");
  GrabBoth(*viewer, "remote", &call);
  EXPECT_EQ(call.error_code(), grpc::StatusCode::PERMISSION_DENIED) << call.error_message();

  // The station (operator) grabs; the capture records who asked.
  auto operator_stub = TlsStub(port, pki.ca(), station);
  const v1::GrabResponse grab = GrabBoth(*operator_stub, "remote", &call);
  ASSERT_TRUE(call.ok()) << call.error_message();
  EXPECT_EQ(grab.capture().requested_by(), "station");

  // A certificate of the right CA whose name has no role: refused by role.
  auto unknown = TlsStub(port, pki.ca(), stranger);
  call = unknown->GetStatus(Deadline(milliseconds(10000)).get(), {}, &status);
  EXPECT_EQ(call.error_code(), grpc::StatusCode::PERMISSION_DENIED) << call.error_message();

  // No client certificate, or one signed by another CA: the handshake fails, every time.
  int successes = 0;
  for (int i = 0; i < 20; ++i) {
    auto anonymous = TlsStub(port, pki.ca(), PemFiles{});
    auto impostor = TlsStub(port, pki.ca(), forged);
    for (auto* stub : {anonymous.get(), impostor.get()}) {
      call = stub->GetStatus(Deadline(milliseconds(5000)).get(), {}, &status);
      successes += call.ok();
      EXPECT_EQ(call.error_code(), grpc::StatusCode::UNAVAILABLE) << call.error_message();
    }
  }
  EXPECT_EQ(successes, 0);

  // The local socket is unaffected, and the remote grab is in the store.
  auto local = daemon_->Stub();
  ASSERT_TRUE(local->GetStatus(Deadline(milliseconds(5000)).get(), {}, &status).ok());
  EXPECT_EQ(status.captures_stored(), 1u);
}

// Every role tried on every call (roles.h): uids 60001-60004 are viewer,
// operator, admin and nobody-in-particular.
TEST_F(Bslsd, EveryRoleOnEveryCallHasNoUnauthorizedSuccess) {
  if (::geteuid() != 0) GTEST_SKIP() << "needs root to run the probe as other uids";
  Start("roles",
        "roles:\n  viewer: ['60001']\n  operator: ['60002']\n  admin: [root, '60003']\n"
        "  others: none\n" +
            std::string(kSimulatedSlides));
  const std::map<std::string, int> required = {
      {"GetStatus", 1},     {"StreamPreview", 1}, {"ListCaptures", 1}, {"GetCapture", 1},
      {"GetSlideState", 1}, {"WatchEvents", 1},   {"SelectCamera", 2}, {"SetGain", 2},
      {"Grab", 2},          {"SetSlide", 2},      {"SetFocus", 2},     {"SetLamp", 2},
      {"DeleteCapture", 3}};
  int unauthorized_successes = 0;
  const std::string probe = bsls::testing::RoleProbePath();
  for (const auto& [uid, role] :
       std::vector<std::pair<uid_t, int>>{{60001, 1}, {60002, 2}, {60003, 3}, {60004, 0}}) {
    int pipe_fds[2];
    ASSERT_EQ(::pipe(pipe_fds), 0);
    const pid_t child = ::fork();
    if (child == 0) {
      ::dup2(pipe_fds[1], 1);
      ::close(pipe_fds[0]);
      // The socket's group (mode 0660) lets the probe connect; its role comes from its uid.
      const gid_t socket_group = kTestSocketGroup;
      if (::setgroups(1, &socket_group) != 0 || ::setgid(uid) != 0 || ::setuid(uid) != 0)
        ::_exit(3);
      ::execl(probe.c_str(), probe.c_str(), daemon_->socket().c_str(), nullptr);
      ::_exit(127);
    }
    ::close(pipe_fds[1]);
    std::string output;
    char buffer[4096];
    for (ssize_t n; (n = ::read(pipe_fds[0], buffer, sizeof buffer)) > 0;) output.append(buffer, n);
    ::close(pipe_fds[0]);
    int status = 0;
    ::waitpid(child, &status, 0);
    ASSERT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << "probe as uid " << uid;
    std::istringstream lines(output);
    std::set<std::string> seen;
    for (std::string method; lines >> method;) {
      int code = -1;
      lines >> code;
      seen.insert(method);
      const bool let_through = code != static_cast<int>(grpc::StatusCode::PERMISSION_DENIED) &&
                               code != static_cast<int>(grpc::StatusCode::UNAUTHENTICATED);
      const bool allowed = role >= required.at(method);
      if (let_through && !allowed) ++unauthorized_successes;
      EXPECT_EQ(let_through, allowed) << "uid " << uid << " " << method << " -> code " << code;
    }
    EXPECT_EQ(seen.size(), required.size()) << output;
  }
  EXPECT_EQ(unauthorized_successes, 0);
  v1::DeviceStatus device;
  EXPECT_TRUE(daemon_->Stub()->GetStatus(Deadline(milliseconds(5000)).get(), {}, &device).ok());
}

// The fields of a /proc/<pid>/task/<tid>/status, each split at white space.
std::map<std::string, std::vector<std::string>> StatusFields(const fs::path& status) {
  std::ifstream in(status);
  std::map<std::string, std::vector<std::string>> fields;
  for (std::string line; std::getline(in, line);) {
    std::istringstream words(line);
    std::string key;
    words >> key;
    for (std::string word; words >> word;) fields[key].push_back(word);
  }
  return fields;
}

// Started as root, bslsd sets up its socket (with a group root is needed
// for) and becomes the configured user: uid, gid and groups, no
// capabilities, no_new_privs, in every thread; it still grabs and stores.
TEST_F(Bslsd, StartedAsRootItBecomesTheConfiguredUserWithoutPrivileges) {
  if (::geteuid() != 0)
    GTEST_SKIP() << "needs root: bslsd switches users only when started as root";
  constexpr uid_t kUid = 60010;
  constexpr gid_t kGid = 60011;
  dir_ = MakeDaemonDir("identity");
  ASSERT_EQ(::chown(dir_.c_str(), kUid, kGid), 0);  // its store and socket live here
  config_ = WriteDaemonConfig(dir_, "roles:\n  admin: [root]\n" + std::string(kSimulatedSlides));
  daemon_ = std::make_unique<DaemonProcess>(
      dir_, config_,
      std::vector<std::string>{
          "--set", "user=\"" + std::to_string(kUid) + ":" + std::to_string(kGid) + "\""});
  ASSERT_TRUE(daemon_->ready()) << daemon_->Log();
  const std::vector<std::string> uid(4, std::to_string(kUid));
  const std::vector<std::string> gid(4, std::to_string(kGid));
  const std::vector<std::string> no_capability = {"0000000000000000"};
  std::size_t threads = 0;
  for (const auto& task :
       fs::directory_iterator("/proc/" + std::to_string(daemon_->pid()) + "/task")) {
    auto fields = StatusFields(task.path() / "status");
    EXPECT_EQ(fields["Uid:"], uid) << task.path();
    EXPECT_EQ(fields["Gid:"], gid) << task.path();
    EXPECT_TRUE(fields["Groups:"].empty()) << task.path();
    EXPECT_EQ(fields["CapEff:"], no_capability) << task.path();
    EXPECT_EQ(fields["CapPrm:"], no_capability) << task.path();
    EXPECT_EQ(fields["CapAmb:"], no_capability) << task.path();
    EXPECT_EQ(fields["NoNewPrivs:"], std::vector<std::string>{"1"}) << task.path();
    ++threads;
  }
  EXPECT_GT(threads, 1u);
  // The socket got its group while bslsd could still set it.
  struct stat socket_file {};
  ASSERT_EQ(::stat(daemon_->socket().c_str(), &socket_file), 0);
  EXPECT_EQ(socket_file.st_gid, kTestSocketGroup);
  EXPECT_EQ(socket_file.st_mode & 0777, 0660u);
  auto stub = daemon_->Stub();
  grpc::Status grab;
  GrabBoth(*stub, "identity", &grab);
  ASSERT_TRUE(grab.ok()) << grab.error_message();
  struct stat store {};
  ASSERT_EQ(::stat((dir_ / "store").c_str(), &store), 0);
  EXPECT_EQ(store.st_uid, kUid);
}

// Bytes that are not the request message get INVALID_ARGUMENT naming the
// message type, on every method of bslsd (gRPC alone gives INTERNAL with an
// empty message), before any role is checked; the daemon still answers.
TEST_F(Bslsd, AMalformedRequestIsInvalidArgumentWithAMessage) {
  Start("malformed");
  grpc::GenericStub stub(daemon_->Channel());
  const google::protobuf::ServiceDescriptor* service =
      google::protobuf::DescriptorPool::generated_pool()->FindServiceByName(
          v1::CaptureDaemon::service_full_name());
  ASSERT_NE(service, nullptr);
  // bslsd takes no request stream: every method is tried.
  EXPECT_EQ(processing::test::ExpectMalformedRequestsRefused(stub, *service),
            service->method_count());
  v1::DeviceStatus status;
  EXPECT_TRUE(daemon_->Stub()->GetStatus(Deadline(milliseconds(5000)).get(), {}, &status).ok());
}

// The configured connection limits reach bslsd's socket: one
// user's connections beyond listen.max_connections_per_user are closed at
// once, and once they are gone the daemon takes that user's connections
// again. The user is not this process's: the start-up probe's gRPC
// connection (which gRPC may keep when the daemon accepted it late) counts
// against root's share, not against the one tried here.
TEST_F(Bslsd, AUsersConnectionsBeyondItsShareAreClosedAtOnce) {
  if (::geteuid() != 0) GTEST_SKIP() << "needs root to connect as another uid";
  Start("connections", kSimulatedSlides,
        {"--set", "listen.max_connections_per_user=3", "--set", "listen.max_connections=100"});
  constexpr uid_t kCaller = 60001;  // in the socket's group, not its owner
  const std::string socket = daemon_->socket().string();
  std::vector<int> open;
  int closed = 0;
  for (int i = 0; i < 5; ++i) {
    const int fd = ConnectUnixAs(kCaller, socket, kTestSocketGroup);
    ASSERT_GE(fd, 0);
    if (ClosedWithin(fd, 1000)) {
      ++closed;
      ::close(fd);
    } else {
      open.push_back(fd);
    }
  }
  EXPECT_EQ(open.size(), 3u) << daemon_->Log();
  EXPECT_EQ(closed, 2);
  for (int fd : open) ::close(fd);
  // The share is free again once the daemon saw them go.
  bool taken_again = false;
  for (int attempt = 0; attempt < 20 && !taken_again; ++attempt) {
    std::this_thread::sleep_for(milliseconds(250));
    const int fd = ConnectUnixAs(kCaller, socket, kTestSocketGroup);
    ASSERT_GE(fd, 0);
    taken_again = !ClosedWithin(fd, 1000);
    ::close(fd);
  }
  EXPECT_TRUE(taken_again) << daemon_->Log();
  v1::DeviceStatus status;
  EXPECT_TRUE(daemon_->Stub()->GetStatus(Deadline(milliseconds(5000)).get(), {}, &status).ok());
}

// HTTP/2 limits are set on the server: a connection without calls
// is closed after listen.max_connection_idle_ms, and the client reconnects.
TEST_F(Bslsd, AConnectionWithoutCallsIsClosedAfterTheIdleLimit) {
  Start("idle", kSimulatedSlides, {"--set", "listen.max_connection_idle_ms=500"});
  grpc::ChannelArguments args;
  args.SetInt(GRPC_ARG_USE_LOCAL_SUBCHANNEL_POOL, 1);
  std::shared_ptr<grpc::Channel> channel = daemon_->Channel(args);
  auto stub = v1::CaptureDaemon::NewStub(channel);
  v1::DeviceStatus status;
  ASSERT_TRUE(stub->GetStatus(Deadline(milliseconds(5000)).get(), {}, &status).ok());
  ASSERT_EQ(channel->GetState(false), GRPC_CHANNEL_READY);
  const auto until = std::chrono::steady_clock::now() + seconds(10);
  while (channel->GetState(false) == GRPC_CHANNEL_READY && std::chrono::steady_clock::now() < until)
    std::this_thread::sleep_for(milliseconds(50));
  EXPECT_NE(channel->GetState(false), GRPC_CHANNEL_READY) << "the idle connection stayed open";
  EXPECT_TRUE(stub->GetStatus(Deadline(milliseconds(5000)).get(), {}, &status).ok());
}

TEST(BslsdConfig, CheckConfigNamesTheBadKeyAndExitsWithConfigError) {
  const fs::path dir = MakeDaemonDir("check");
  const fs::path config = WriteDaemonConfig(dir);
  const std::string command = bsls::testing::BslsdPath() + " --check-config --config " +
                              config.string() + " --set framestore.backend=firewire 2>&1";
  FILE* pipe = ::popen(command.c_str(), "r");
  ASSERT_NE(pipe, nullptr);
  std::string output;
  char buffer[1024];
  while (std::fgets(buffer, sizeof buffer, pipe)) output += buffer;
  const int status = ::pclose(pipe);
  EXPECT_EQ(WEXITSTATUS(status), 78) << output;
  EXPECT_NE(output.find("framestore.backend"), std::string::npos) << output;
  EXPECT_NE(output.find("firewire"), std::string::npos) << output;

  const std::string ok_command =
      bsls::testing::BslsdPath() + " --check-config --config " + config.string() + " 2>&1";
  pipe = ::popen(ok_command.c_str(), "r");
  output.clear();
  while (std::fgets(buffer, sizeof buffer, pipe)) output += buffer;
  EXPECT_EQ(WEXITSTATUS(::pclose(pipe)), 0) << output;
  EXPECT_NE(output.find("configuration OK"), std::string::npos) << output;
}

// Runs `command` (stderr with stdout): its exit code and what it printed.
std::pair<int, std::string> RunCommand(const std::string& command) {
  FILE* pipe = ::popen((command + " 2>&1").c_str(), "r");
  if (pipe == nullptr) return {-1, "popen failed"};
  std::string output;
  char buffer[1024];
  while (std::fgets(buffer, sizeof buffer, pipe)) output += buffer;
  const int status = ::pclose(pipe);
  return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, output};
}

// A world-writable socket would let every local user call the
// daemon; such a mode is refused, naming the key and the reason.
TEST(BslsdConfig, AWorldWritableSocketModeIsRefused) {
  const fs::path dir = MakeDaemonDir("mode");
  const fs::path config = WriteDaemonConfig(dir);
  for (const char* mode : {"0666", "0602", "0777", "2"}) {
    const auto [code, output] =
        RunCommand(bsls::testing::BslsdPath() + " --check-config --config " + config.string() +
                   " --set 'listen.socket_mode=\"" + mode + "\"'");
    EXPECT_EQ(code, 78) << mode << ": " << output;
    EXPECT_NE(output.find("listen.socket_mode"), std::string::npos) << output;
    EXPECT_NE(output.find("world-writable"), std::string::npos) << output;
  }
  const auto [code, output] = RunCommand(bsls::testing::BslsdPath() + " --check-config --config " +
                                         config.string() + " --set 'listen.socket_mode=\"0660\"'");
  EXPECT_EQ(code, 0) << output;
}

// The guard's frame budgets are keys of `listen:`: out of range or a
// connection's budget above the total is refused naming the keys.
TEST(BslsdConfig, GuardBudgetsAreBoundedKeys) {
  const fs::path dir = MakeDaemonDir("guard_keys");
  const fs::path config = WriteDaemonConfig(dir);
  const std::string check =
      bsls::testing::BslsdPath() + " --check-config --config " + config.string();
  {
    const auto [code, output] = RunCommand(check + " --set listen.guard_frames_per_second=0");
    EXPECT_EQ(code, 78) << output;
    EXPECT_NE(output.find("listen.guard_frames_per_second"), std::string::npos) << output;
  }
  {
    const auto [code, output] = RunCommand(check + " --set listen.guard_burst=5000");
    EXPECT_EQ(code, 78) << output;
    EXPECT_NE(output.find("listen.guard_burst is above listen.guard_total_burst"),
              std::string::npos)
        << output;
  }
  const auto [code, output] = RunCommand(check + " --set listen.guard_frames_per_second=50");
  EXPECT_EQ(code, 0) << output;
}

// bslsd reads the head of each calibration file (format, version, side):
// a file of the other side, or of another format, stops the start with the
// key and the reason, before anything is served.
TEST(BslsdConfig, ACalibrationOfTheOtherSideOrFormatIsRefusedAtStart) {
  const fs::path dir = MakeDaemonDir("calibration");
  const fs::path config = WriteDaemonConfig(dir);
  const fs::path right = dir / "right.yaml";
  std::ofstream(right) << "format: bsls-calibration\nformat_version: 1\n"
                          "software_version: test\nside: right\n";
  const fs::path other = dir / "other.yaml";
  std::ofstream(other) << "format: other\nformat_version: 1\nside: left\n";
  for (const auto& [file, expected] :
       {std::pair{right, std::string("is a calibration of the other side")},
        std::pair{other, std::string("format is 'other'")}}) {
    const auto [code, output] =
        RunCommand("timeout 60 " + bsls::testing::BslsdPath() + " --config " + config.string() +
                   " --set processing.calibration_left=" + file.string());
    EXPECT_EQ(code, 78) << output;
    EXPECT_NE(output.find("processing.calibration_left"), std::string::npos) << output;
    EXPECT_NE(output.find(expected), std::string::npos) << output;
  }
}

// Started as root with a `user` that does not exist, bslsd
// refuses to start (it never serves as root by accident) and names it.
TEST(BslsdConfig, StartedAsRootWithAnUnknownUserItRefusesToStart) {
  if (::geteuid() != 0) GTEST_SKIP() << "needs root: the user matters only when started as root";
  const fs::path dir = MakeDaemonDir("nouser");
  const fs::path config = WriteDaemonConfig(dir);
  const auto [code, output] = RunCommand(bsls::testing::BslsdPath() + " --config " +
                                         config.string() + " --set user=no-such-bsls-user");
  EXPECT_EQ(code, 78) << output;
  EXPECT_NE(output.find("'no-such-bsls-user' does not exist"), std::string::npos) << output;
  EXPECT_FALSE(fs::exists(dir / "bslsd.sock")) << "it opened its socket before refusing";
}

}  // namespace
}  // namespace bsls::testing
