// The attack suite of issue 26 ("Fuzzing and tests", "Done means"): each
// class of hostile request the outside probe found, sent to the services
// running as real processes, and what the issue promises afterwards.
//
// bsls-processd, fresh, with 2 workers: every class is sent twice at once
// (two such calls used to take every worker), each call with a deadline.
// For every class:
//   * every call is answered (any status) within its deadline + 1 s;
//   * 3 s after the last answer GetServerInfo reports no worker busy and
//     nothing queued (the service's own account of its pool);
//   * its open descriptors (/proc/PID/fd) are back within kFdSlack of the
//     baseline taken after a warm-up;
// after each connection flood its resident memory (VmRSS) is back within
// 20 % of what it was before the flood; at the end SIGTERM ends it with
// code 0 within 10 s.
//
// The classes: YAML alias recursion (`a: &a [*a]`, `&a {k: *a}`) and the
// 10-level alias bomb as Calibrate manifests; a PLY surface with
// `element junk 18446744073709551615`; a frame above the pixel budget; a
// noise frame at the budget and the slow hostile frame (hostile_frame.h),
// each with a short deadline; calibration images above the pixel budget
// (PNGs of 8192 x 8192, refused: they used to be decoded and searched
// until the deadline); malformed protobuf bytes on every method;
// out-of-range enums; 60 KB texts the service might echo; 200 connections
// held open on the Unix socket and on TCP.
//
// bslsd: descriptor exhaustion (started with a soft limit of 160 descriptors
// and flooded with connections: it must not spin, and must serve again once
// the flood ends), preview readers that read nothing (their slots come
// back), malformed bytes on every method, out-of-range enums, a 60 KB page
// token; the same checks of answers, descriptors, memory and shutdown.
//
// The bounds are the issue's, for a release build: the test is labelled
// `timing` and stays out of the sanitizer stage (malformed_requests_test
// sends the same kinds of bytes there).
#include <google/protobuf/stubs/logging.h>
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <sys/resource.h>
#include <zlib.h>

#include <algorithm>
#include <cstdio>
#include <functional>
#include <future>
#include <opencv2/imgcodecs.hpp>
#include <thread>

#include "bsls/contract/frame_message.h"
#include "bsls/testing/build_paths.h"
#include "bsls/testing/hostile_frame.h"
#include "bsls/testing/raw_connections.h"
#include "bsls/v1/capture.grpc.pb.h"
#include "bsls/v1/processing.grpc.pb.h"
#include "daemon_process.h"
#include "processd_process.h"
#include "raw_calls.h"

namespace bsls::processing::test {
namespace {

using Clock = std::chrono::steady_clock;
using grpc::StatusCode;
using std::chrono::milliseconds;
using std::chrono::seconds;

constexpr double kAnswerSlackS = 1.0;         // answered within deadline + this
constexpr auto kBusyCheckAfter = seconds(3);  // then no worker busy
constexpr int kFdSlack = 4;                   // gRPC's own timers and wakeup fds
constexpr double kRssGrowth = 1.20;           // after a flood, within 20 % of before
constexpr auto kSettle = seconds(10);         // descriptors and memory may take this long
constexpr auto kShutdown = seconds(10);       // SIGTERM to exit
constexpr int kFloodConnections = 200;
constexpr std::size_t kMaxMessageBytes = 1024;  // an error message echoes a short prefix only

// The wire bytes of `message`.
std::string Bytes(const pb::Message& message) {
  std::string bytes;
  message.SerializePartialToString(&bytes);
  return bytes;
}

// A message that does not parse as any protobuf: field 1, length-delimited,
// claiming 2^35 bytes.
const std::string kMalformed("\x0a\xff\xff\xff\xff\x7f", 6);

// A channel on a connection of its own.
std::shared_ptr<grpc::Channel> OwnChannel(const std::string& target) {
  static std::atomic<int> n{0};
  grpc::ChannelArguments args;
  args.SetInt("bsls.test.attack", n++);
  args.SetInt(GRPC_ARG_USE_LOCAL_SUBCHANNEL_POOL, 1);
  args.SetMaxReceiveMessageSize(16 << 20);
  args.SetMaxSendMessageSize(64 << 20);
  return grpc::CreateCustomChannel(target, grpc::InsecureChannelCredentials(), args);
}

// One hostile class: the call (sent `copies` times at once, each on its own
// connection), and what its answer must be besides timely.
struct Attack {
  std::string name;
  RawCall call;
  int copies = 2;
  std::vector<StatusCode> expected;  // empty: any status
};

// Sends every copy of every attack in `group` at once, each on its own
// connection; expects each answered in time, with an expected status and a
// short message. Returns when the last one ended.
void Send(const std::string& target, const std::vector<Attack>& group) {
  std::vector<std::pair<const Attack*, std::future<RawOutcome>>> calls;
  for (const Attack& attack : group)
    for (int i = 0; i < attack.copies; ++i)
      calls.emplace_back(&attack, std::async(std::launch::async, [&target, &attack] {
        grpc::GenericStub stub(OwnChannel(target));
        return SendRaw(stub, attack.call);
      }));
  for (auto& [attack, call] : calls) {
    const RawOutcome out = call.get();
    const double limit = attack->call.deadline_ms / 1000.0 + kAnswerSlackS;
    std::printf("  %-44s status %2d after %6.3f s (limit %4.1f s): %.100s\n", attack->name.c_str(),
                out.code, out.seconds, limit, out.message.c_str());
    EXPECT_FALSE(out.hung) << attack->name;
    EXPECT_LE(out.seconds, limit) << attack->name << ": answered after " << out.seconds << " s";
    if (!attack->expected.empty()) {
      EXPECT_NE(std::find(attack->expected.begin(), attack->expected.end(), out.code),
                attack->expected.end())
          << attack->name << ": status " << out.code << " " << out.message;
    }
    EXPECT_LE(out.message.size(), kMaxMessageBytes)
        << attack->name << ": the message echoes " << out.message.size() << " bytes";
    EXPECT_NE(out.code, StatusCode::UNKNOWN) << attack->name << ": " << out.message;
  }
  std::fflush(stdout);
}

// Waits up to kSettle for `pid`'s descriptors to come back to `baseline` + kFdSlack.
int SettledFds(pid_t pid, int baseline) {
  const auto until = Clock::now() + kSettle;
  int fds = OpenDescriptors(pid);
  while (fds > baseline + kFdSlack && Clock::now() < until) {
    std::this_thread::sleep_for(milliseconds(200));
    fds = OpenDescriptors(pid);
  }
  return fds;
}

// Waits up to kSettle for `pid`'s resident memory to come back within
// kRssGrowth of `before_kib`.
long SettledRss(pid_t pid, long before_kib) {
  const auto until = Clock::now() + kSettle;
  long rss = ResidentKib(pid);
  while (rss > before_kib * kRssGrowth && Clock::now() < until) {
    std::this_thread::sleep_for(milliseconds(250));
    rss = ResidentKib(pid);
  }
  return rss;
}

// `n` connections to the Unix socket at `path` (those the server took).
std::vector<int> UnixFlood(const std::string& path, int n) {
  std::vector<int> fds;
  for (int i = 0; i < n; ++i) {
    const int fd = testing::ConnectUnixAs(0, path);
    if (fd >= 0) fds.push_back(fd);
  }
  return fds;
}

// `n` TCP connections to 127.0.0.1:`port` from 127.0.0.2: another peer
// than the test's callers (from 127.0.0.1), whom the per-address limit
// (listen.max_tcp_connections_per_peer) would otherwise refuse while the
// flood holds its share.
std::vector<int> TcpFlood(int port, int n) {
  std::vector<int> fds;
  for (int i = 0; i < n; ++i) {
    const int fd = testing::ConnectTcpFrom("127.0.0.2", port);
    if (fd >= 0) fds.push_back(fd);
  }
  return fds;
}

// Closes every connection of `fds` and empties it.
void CloseAll(std::vector<int>* fds) {
  for (const int fd : *fds) ::close(fd);
  fds->clear();
}

// A PNG of `side` x `side` black 8-bit grey pixels (compresses to a few
// hundred KiB at most: the upload is small, the image is not).
std::string BlackPng(int side) {
  std::string raw;
  raw.reserve(static_cast<std::size_t>(side + 1) * side);
  for (int y = 0; y < side; ++y) raw.append(static_cast<std::size_t>(side) + 1, '\0');
  uLongf size = compressBound(static_cast<uLong>(raw.size()));
  std::string idat(size, '\0');
  compress2(reinterpret_cast<Bytef*>(idat.data()), &size,
            reinterpret_cast<const Bytef*>(raw.data()), static_cast<uLong>(raw.size()), 9);
  idat.resize(size);
  auto be32 = [](std::string* out, std::uint32_t v) {
    for (int shift = 24; shift >= 0; shift -= 8) out->push_back(static_cast<char>(v >> shift));
  };
  auto chunk = [&](std::string* out, const std::string& type, const std::string& data) {
    be32(out, static_cast<std::uint32_t>(data.size()));
    const std::string body = type + data;
    *out += body;
    be32(out, static_cast<std::uint32_t>(crc32(0, reinterpret_cast<const Bytef*>(body.data()),
                                               static_cast<uInt>(body.size()))));
  };
  std::string png("\x89PNG\r\n\x1a\n", 8);
  std::string ihdr;
  be32(&ihdr, static_cast<std::uint32_t>(side));
  be32(&ihdr, static_cast<std::uint32_t>(side));
  ihdr += std::string("\x08\x00\x00\x00\x00", 5);
  chunk(&png, "IHDR", ihdr);
  chunk(&png, "IDAT", idat);
  chunk(&png, "IEND", "");
  return png;
}

// A Calibrate call: the manifest, then `files` (name, bytes), each one chunk.
RawCall CalibrateCall(const std::string& manifest,
                      const std::vector<std::pair<std::string, std::string>>& files,
                      int deadline_ms) {
  RawCall call;
  call.method = "/bsls.v1.Processing/Calibrate";
  call.deadline_ms = deadline_ms;
  v1::CalibrateRequest first;
  first.mutable_manifest()->set_yaml(manifest);
  call.messages.push_back(Bytes(first));
  for (const auto& [name, data] : files) {
    v1::CalibrateRequest part;
    part.mutable_file()->set_path(name);
    part.mutable_file()->set_data(data);
    part.mutable_file()->set_last(true);
    call.messages.push_back(Bytes(part));
  }
  return call;
}

// One request message of `bytes` to `method` ("/bsls.v1.Service/Method").
RawCall UnaryCall(const std::string& method, const std::string& bytes, int deadline_ms) {
  RawCall call;
  call.method = method;
  call.messages = {bytes};
  call.deadline_ms = deadline_ms;
  return call;
}

// The alias bomb: ten levels of eight references each (8^10 nodes
// for a walk that follows aliases).
std::string AliasBomb() {
  std::string yaml = "a0: &a0 [x, x, x, x, x, x, x, x]\n";
  for (int i = 1; i < 10; ++i) {
    const std::string prev = "*a" + std::to_string(i - 1);
    yaml += "a" + std::to_string(i) + ": &a" + std::to_string(i) + " [" + prev;
    for (int k = 1; k < 8; ++k) yaml += ", " + prev;
    yaml += "]\n";
  }
  return yaml;
}

// A manifest of a left session naming t0..t2 and s0..s2.
std::string SessionManifest() {
  return "side: left\ntarget: {rows: 8, cols: 8, pitch_mm: 6.5, square_mm: 4}\n"
         "camera_views:\n  - {image: t0.png, z_mm: 0}\n  - {image: t1.png, z_mm: 50}\n"
         "  - {image: t2.png, z_mm: 100}\n"
         "screen_views:\n  - {image: s0.png, z_mm: 0}\n  - {image: s1.png, z_mm: 60}\n"
         "  - {image: s2.png, z_mm: 120}\n"
         "pattern: {lines: 20, rows: 24}\n";
}

// A small valid binary PLY triangle, with `header_extra` lines before its
// vertex element.
std::string PlyTriangle(const std::string& header_extra) {
  std::string ply = "ply\nformat binary_little_endian 1.0\n" + header_extra +
                    "element vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
                    "element face 1\nproperty list uchar int vertex_indices\nend_header\n";
  const float v[9] = {0, 0, 0, 10, 0, 0, 0, 10, 0};
  ply.append(reinterpret_cast<const char*>(v), sizeof v);
  ply += '\x03';
  const std::int32_t f[3] = {0, 1, 2};
  ply.append(reinterpret_cast<const char*>(f), sizeof f);
  return ply;
}

// A ProcessFrame request of `grey` (8-bit) as a left frame, nothing else asked.
v1::ProcessFrameRequest FrameRequest(const cv::Mat& grey) {
  v1::ProcessFrameRequest request;
  contract::ToFrameMessage(grey, request.mutable_frame());
  request.set_side(v1::SIDE_LEFT);
  return request;
}

// Protobuf's log handler here: fatal messages only (the malformed bytes make
// it complain on the client side too).
void QuietProtobuf(pb::LogLevel level, const char*, int, const std::string& text) {
  if (level >= pb::LOGLEVEL_FATAL) std::fprintf(stderr, "%s\n", text.c_str());
}

// ---------------------------------------------------------------------------

TEST(AttackSuite, ProcessdWithTwoWorkersStaysAliveFreeAndClean) {
  pb::SetLogHandler(&QuietProtobuf);
  const fs::path folder = MakeTempFolder("bsls_attack_processd_");
  const fs::path socket = folder / "processd.sock";
  ProcessdProcess processd(bsls::testing::ProcessdPath(), folder, "attack", 2, {}, seconds(120),
                           "127.0.0.1:0", socket.string());
  ASSERT_TRUE(processd.ready()) << processd.Log();
  const std::string target = processd.address();
  auto info_stub = v1::Processing::NewStub(OwnChannel(target));
  auto server_info = [&](v1::ServerInfo* info) {
    grpc::ClientContext context;
    context.set_deadline(std::chrono::system_clock::now() + seconds(2));
    return info_stub->GetServerInfo(&context, {}, info);
  };
  v1::ServerInfo info;
  ASSERT_TRUE(server_info(&info).ok());
  ASSERT_EQ(info.workers(), 2u);

  // Warm-up: a small frame decoded on each worker, so that gRPC's pools and
  // the allocator's arenas have their working size before the baseline.
  cv::Mat noise(64, 64, CV_8UC1);
  cv::randu(noise, 0, 256);
  Send(target, {{"warm-up: a small frame",
                 UnaryCall("/bsls.v1.Processing/ProcessFrame", Bytes(FrameRequest(noise)), 20000),
                 2,
                 {StatusCode::OK, StatusCode::FAILED_PRECONDITION}}});
  std::this_thread::sleep_for(seconds(1));
  const int base_fds = OpenDescriptors(processd.pid());
  const long base_rss = ResidentKib(processd.pid());
  std::printf("bsls-processd baseline: %d fds, %ld KiB\n", base_fds, base_rss);

  // After each class: the workers free 3 s after the last answer, the
  // descriptors back to the baseline.
  auto after = [&](const std::string& name) {
    std::this_thread::sleep_for(kBusyCheckAfter);
    v1::ServerInfo now;
    const grpc::Status status = server_info(&now);
    ASSERT_TRUE(status.ok()) << name << ": GetServerInfo " << status.error_message() << "\n"
                             << processd.Log();
    EXPECT_EQ(now.busy(), 0u) << name << ": a worker is still busy 3 s after the last answer";
    EXPECT_EQ(now.waiting(), 0u) << name << ": work is still queued 3 s after the last answer";
    const int fds = SettledFds(processd.pid(), base_fds);
    EXPECT_LE(fds, base_fds + kFdSlack)
        << name << ": descriptors " << fds << ", baseline " << base_fds;
    ASSERT_FALSE(processd.exited()) << name << " ended the service\n" << processd.Log();
  };
  // Each group is sent at once: at most six work calls, what the two
  // workers and their queue of four take, so that every call reaches the
  // code under attack instead of RESOURCE_EXHAUSTED.
  auto run = [&](const std::string& group, const std::vector<Attack>& attacks) {
    SCOPED_TRACE(group);
    Send(target, attacks);
    after(group);
  };
  const std::vector<StatusCode> refused = {StatusCode::INVALID_ARGUMENT};

  // YAML: alias recursion and the alias bomb, as Calibrate manifests, then
  // as calibration files sent inline.
  run("YAML manifests",
      {{"manifest a: &a [*a]", CalibrateCall("a: &a [*a]\n", {}, 5000), 2, refused},
       {"manifest &a {k: *a}", CalibrateCall("&a {k: *a}\n", {}, 5000), 2, refused},
       {"manifest alias bomb (10 levels)", CalibrateCall(AliasBomb(), {}, 5000), 2, refused}});
  {
    v1::PutCalibrationRequest map_alias;
    map_alias.set_yaml("&a {k: *a}\n");
    v1::PutCalibrationRequest bomb;
    bomb.set_yaml(AliasBomb());
    // PLY: an element of 2^64 - 1 items without properties (skipped: they
    // take no bytes), and one of 2^64 - 1 items of a byte each (refused).
    v1::MeasureRequest no_properties;
    no_properties.set_surface_ply(PlyTriangle("element junk 18446744073709551615\n"));
    v1::PointXY* h = no_properties.mutable_measurements()->add_heights();
    h->set_x(1);
    h->set_y(1);
    v1::MeasureRequest one_byte = no_properties;
    one_byte.set_surface_ply(PlyTriangle("element junk 18446744073709551615\nproperty uchar a\n"));
    run("YAML calibration files, PLY counts",
        {{"calibration file &a {k: *a}",
          UnaryCall("/bsls.v1.Processing/PutCalibration", Bytes(map_alias), 5000), 2, refused},
         {"calibration file alias bomb",
          UnaryCall("/bsls.v1.Processing/PutCalibration", Bytes(bomb), 5000), 2, refused},
         {"PLY element junk 18446744073709551615",
          UnaryCall("/bsls.v1.Processing/Measure", Bytes(no_properties), 5000),
          2,
          {StatusCode::OK}},
         {"PLY 2^64 - 1 items of one byte",
          UnaryCall("/bsls.v1.Processing/Measure", Bytes(one_byte), 5000), 2, refused}});
  }

  // Frames: above the budget (refused), at it with a short deadline, and
  // the slow hostile frame with a shorter one; each pair alone, so that
  // both take a worker at once.
  {
    const cv::Mat above(4096, 4096, CV_8UC1, cv::Scalar(128));
    run("frame above the budget",
        {{"frame 4096 x 4096 (above the budget)",
          UnaryCall("/bsls.v1.Processing/ProcessFrame", Bytes(FrameRequest(above)), 10000), 2,
          refused}});
    cv::Mat at(2896, 2896, CV_8UC1);
    cv::randu(at, 0, 256);
    run("frame at the budget",
        {{"noise frame 2896 x 2896 (at the budget), 1 s",
          UnaryCall("/bsls.v1.Processing/ProcessFrame", Bytes(FrameRequest(at)), 1000),
          2,
          {}}});
    run("slow frame", {{"hostile frame, deadline 300 ms",
                        UnaryCall("/bsls.v1.Processing/ProcessFrame",
                                  Bytes(FrameRequest(testing::HostileFrame())), 300),
                        2,
                        {}}});
  }

  // Calibration images above the pixel budget: six PNGs of 8192 x 8192.
  {
    const std::string big = BlackPng(8192);
    std::vector<std::pair<std::string, std::string>> files;
    for (const char* name : {"t0.png", "t1.png", "t2.png", "s0.png", "s1.png", "s2.png"})
      files.emplace_back(name, big);
    run("calibration images above the budget",
        {{"calibration images 8192 x 8192", CalibrateCall(SessionManifest(), files, 5000), 2,
          refused}});
  }

  // Malformed protobuf on every method.
  {
    std::vector<Attack> malformed;
    for (const char* method : {"ProcessFrame", "ReconstructSession", "Measure", "Calibrate",
                               "PutCalibration", "GetCalibration", "GetServerInfo"})
      malformed.push_back(
          {std::string("malformed bytes to ") + method,
           UnaryCall(std::string("/bsls.v1.Processing/") + method, kMalformed, 5000), 2, refused});
    run("malformed protobuf", malformed);
  }

  // Out-of-range enums and long texts the service might echo: one call each.
  {
    v1::ProcessFrameRequest side = FrameRequest(noise);
    side.set_side(static_cast<v1::Side>(99));
    v1::ProcessFrameRequest chain = FrameRequest(noise);
    chain.mutable_decode()->set_chain(static_cast<v1::DecodeOptions::Chain>(77));
    v1::ProcessFrameRequest plane = FrameRequest(noise);
    plane.mutable_surface()->set_plane_model(static_cast<v1::SurfaceOptions::PlaneModel>(-3));
    plane.mutable_surface()->set_strips(static_cast<v1::SurfaceOptions::StripMethod>(9));
    v1::ReconstructSessionRequest join;
    contract::ToFrameMessage(noise, join.mutable_left());
    contract::ToFrameMessage(noise, join.mutable_right());
    join.set_join(static_cast<v1::ReconstructSessionRequest::Join>(42));
    v1::GetCalibrationRequest id;
    id.set_id(std::string(60 << 10, 'i'));
    v1::ProcessFrameRequest tag = FrameRequest(noise);
    tag.set_request_tag(std::string(60 << 10, 't'));
    const std::string frame = "/bsls.v1.Processing/ProcessFrame";
    run("enums and long texts",
        {{"side 99", UnaryCall(frame, Bytes(side), 5000), 1, refused},
         {"decode chain 77", UnaryCall(frame, Bytes(chain), 5000), 1, refused},
         {"plane model -3, strips 9", UnaryCall(frame, Bytes(plane), 5000), 1, refused},
         {"join 42", UnaryCall("/bsls.v1.Processing/ReconstructSession", Bytes(join), 5000), 1,
          refused},
         {"calibration id of 60 KB",
          UnaryCall("/bsls.v1.Processing/GetCalibration", Bytes(id), 5000),
          1,
          {StatusCode::INVALID_ARGUMENT, StatusCode::NOT_FOUND}},
         {"request tag of 60 KB", UnaryCall(frame, Bytes(tag), 5000), 1, refused},
         {"manifest path of 60 KB",
          CalibrateCall("side: left\ncamera_views:\n  - {image: " + std::string(60 << 10, 'p') +
                            ", z_mm: 0}\n",
                        {}, 5000),
          1, refused}});
  }

  // Connection floods, on the Unix socket and on TCP: the service keeps
  // serving a caller meanwhile (over TCP: the Unix socket's per-peer limit
  // refuses this uid's further connections while the flood holds them, by
  // design), and gives the descriptors and the memory back.
  for (const bool unix_socket : {true, false}) {
    const std::string name = unix_socket ? "Unix-socket flood" : "TCP flood";
    SCOPED_TRACE(name);
    const long before_rss = ResidentKib(processd.pid());
    std::vector<int> flood = unix_socket ? UnixFlood(socket.string(), kFloodConnections)
                                         : TcpFlood(processd.port(), kFloodConnections);
    std::printf("  %s: %zu connections made\n", name.c_str(), flood.size());
    std::this_thread::sleep_for(milliseconds(500));
    Send(target, {{name + ": a caller meanwhile",
                   UnaryCall("/bsls.v1.Processing/GetServerInfo", "", 2000),
                   2,
                   {StatusCode::OK}}});
    CloseAll(&flood);
    after(name);
    const long rss = SettledRss(processd.pid(), before_rss);
    std::printf("  %s: RSS before %ld KiB, after %ld KiB\n", name.c_str(), before_rss, rss);
    EXPECT_LE(rss, before_rss * kRssGrowth) << name << ": memory not given back";
  }

  std::printf("bsls-processd after the suite: %d fds, %ld KiB\n", OpenDescriptors(processd.pid()),
              ResidentKib(processd.pid()));
  info_stub.reset();
  const auto stop = Clock::now();
  EXPECT_EQ(processd.Terminate(seconds(30)), 0) << processd.Log();
  const double stop_s = std::chrono::duration<double>(Clock::now() - stop).count();
  EXPECT_LE(stop_s, std::chrono::duration<double>(kShutdown).count())
      << "SIGTERM took " << stop_s << " s";
  std::error_code ec;
  if (!HasFailure()) fs::remove_all(folder, ec);
}

// ---------------------------------------------------------------------------

TEST(AttackSuite, BslsdStaysAliveFreeAndClean) {
  pb::SetLogHandler(&QuietProtobuf);
  const fs::path dir = testing::MakeDaemonDir("attack");
  const fs::path config = testing::WriteDaemonConfig(
      dir,
      "roles:\n  admin: [root]\n"
      "limits:\n  max_preview_streams: 2\n  stream_write_timeout_ms: 1000\n");
  // Started with a soft limit of 160 descriptors (the test's own is put
  // back at once), and connection limits above it, so that a flood meets
  // EMFILE in bslsd's accept loop. A connection costs three descriptors
  // (the client's and the socket pair of rpc::Http2Guard): 160 leave room
  // for the ~40 connections of the groups below, the flood's 200 do not fit.
  rlimit saved{};
  ASSERT_EQ(::getrlimit(RLIMIT_NOFILE, &saved), 0);
  rlimit low = saved;
  low.rlim_cur = 160;
  ASSERT_EQ(::setrlimit(RLIMIT_NOFILE, &low), 0);
  testing::DaemonProcess daemon(
      dir, config,
      {"--set", "listen.max_connections=1000", "--set", "listen.max_connections_per_user=1000"});
  ASSERT_EQ(::setrlimit(RLIMIT_NOFILE, &saved), 0);
  ASSERT_TRUE(daemon.ready()) << daemon.Log();
  const std::string target = "unix:" + daemon.socket().string();
  auto status_ok = [&](milliseconds deadline) {
    auto stub = v1::CaptureDaemon::NewStub(OwnChannel(target));
    v1::DeviceStatus status;
    return stub->GetStatus(testing::Deadline(deadline).get(), {}, &status).ok();
  };
  ASSERT_TRUE(status_ok(milliseconds(5000)));
  std::this_thread::sleep_for(seconds(1));
  const int base_fds = OpenDescriptors(daemon.pid());
  const long base_rss = ResidentKib(daemon.pid());
  std::printf("bslsd baseline: %d fds, %ld KiB (soft limit 160)\n", base_fds, base_rss);

  auto after = [&](const std::string& name) {
    std::this_thread::sleep_for(kBusyCheckAfter);
    ASSERT_FALSE(daemon.exited()) << name << " ended bslsd\n" << daemon.Log();
    const auto start = Clock::now();
    EXPECT_TRUE(status_ok(milliseconds(2000))) << name << ": GetStatus not served afterwards";
    EXPECT_LE(Clock::now() - start, milliseconds(2000 + 1000)) << name;
    const int fds = SettledFds(daemon.pid(), base_fds);
    EXPECT_LE(fds, base_fds + kFdSlack)
        << name << ": descriptors " << fds << ", baseline " << base_fds;
  };
  auto run = [&](const std::string& group, const std::vector<Attack>& attacks) {
    SCOPED_TRACE(group);
    Send(target, attacks);
    after(group);
  };
  const std::vector<StatusCode> refused = {StatusCode::INVALID_ARGUMENT};

  // Malformed bytes on every method; out-of-range enums, a 60 KB page token.
  {
    const pb::ServiceDescriptor* service =
        pb::DescriptorPool::generated_pool()->FindServiceByName("bsls.v1.CaptureDaemon");
    ASSERT_NE(service, nullptr);
    std::vector<Attack> malformed;
    for (int i = 0; i < service->method_count(); ++i) {
      const std::string method = service->method(i)->name();
      malformed.push_back({"malformed bytes to " + method,
                           UnaryCall("/bsls.v1.CaptureDaemon/" + method, kMalformed, 3000), 2,
                           refused});
    }
    run("malformed protobuf", malformed);
    v1::SelectCameraRequest select;
    select.set_camera(static_cast<v1::Camera>(99));
    v1::GrabRequest grab;
    grab.set_side(static_cast<v1::GrabSide>(-1));
    v1::ListCapturesRequest list;
    list.set_page_token(std::string(60 << 10, 't'));
    run("enums and long texts",
        {{"camera 99", UnaryCall("/bsls.v1.CaptureDaemon/SelectCamera", Bytes(select), 3000), 2,
          refused},
         {"grab side -1", UnaryCall("/bsls.v1.CaptureDaemon/Grab", Bytes(grab), 3000), 2, refused},
         {"page token of 60 KB",
          UnaryCall("/bsls.v1.CaptureDaemon/ListCaptures", Bytes(list), 3000), 2, refused}});
  }

  // Preview readers that never read and set no deadline: both slots taken,
  // then given back within the write timeout (1 s) and a little.
  {
    SCOPED_TRACE("stalled preview readers");
    grpc::ChannelArguments args;
    args.SetInt(GRPC_ARG_HTTP2_BDP_PROBE, 0);
    args.SetInt(GRPC_ARG_HTTP2_STREAM_LOOKAHEAD_BYTES, 512 * 512);
    std::vector<std::unique_ptr<v1::CaptureDaemon::Stub>> stubs;
    std::vector<std::unique_ptr<grpc::ClientContext>> contexts;
    std::vector<std::unique_ptr<grpc::ClientReader<v1::PreviewFrame>>> readers;
    for (int i = 0; i < 2; ++i) {
      args.SetInt("bsls.test.stalled", i);
      stubs.push_back(v1::CaptureDaemon::NewStub(daemon.Channel(args)));
      contexts.push_back(std::make_unique<grpc::ClientContext>());
      readers.push_back(stubs.back()->StreamPreview(contexts.back().get(), {}));
    }
    std::this_thread::sleep_for(milliseconds(300));
    // A reader with a deadline of 5 s gets frames once the stalled ones lost their slots.
    const auto start = Clock::now();
    bool got_frame = false;
    bool refused_at_first = false;
    for (int attempt = 0; !got_frame && Clock::now() - start < seconds(10); ++attempt) {
      auto stub = v1::CaptureDaemon::NewStub(OwnChannel(target));
      auto context = testing::Deadline(milliseconds(5000));
      auto reader = stub->StreamPreview(context.get(), {});
      v1::PreviewFrame frame;
      got_frame = reader->Read(&frame);
      if (got_frame) context->TryCancel();
      while (reader->Read(&frame)) {
      }
      const grpc::Status status = reader->Finish();
      if (attempt == 0) refused_at_first = status.error_code() == StatusCode::RESOURCE_EXHAUSTED;
      if (!got_frame) std::this_thread::sleep_for(milliseconds(200));
    }
    EXPECT_TRUE(refused_at_first) << "the stalled readers did not hold the slots to begin with";
    const double waited = std::chrono::duration<double>(Clock::now() - start).count();
    std::printf("  stalled preview readers: a reader got a frame after %.2f s\n", waited);
    EXPECT_TRUE(got_frame) << "the stalled readers kept the preview slots";
    EXPECT_LE(waited, 1.0 + 5.0) << "slots came back after " << waited << " s";
    for (std::size_t i = 0; i < readers.size(); ++i) {
      contexts[i]->TryCancel();
      v1::PreviewFrame frame;
      while (readers[i]->Read(&frame)) {
      }
      readers[i]->Finish().IgnoreError();
    }
    readers.clear();
    contexts.clear();
    stubs.clear();
    after("stalled preview readers");
  }

  // Descriptor exhaustion: more connections than bslsd has descriptors.
  // Held for 3 s, they must not make its accept loop spin; once closed, it
  // serves again.
  {
    SCOPED_TRACE("EMFILE flood");
    const long before_rss = ResidentKib(daemon.pid());
    std::vector<int> flood = UnixFlood(daemon.socket().string(), kFloodConnections);
    std::this_thread::sleep_for(milliseconds(300));
    const double cpu_before = CpuSeconds(daemon.pid());
    Send(target, {{"EMFILE flood: a caller meanwhile",
                   UnaryCall("/bsls.v1.CaptureDaemon/GetStatus", "", 2000),
                   1,
                   {}}});
    std::this_thread::sleep_for(seconds(3));
    const double cpu = CpuSeconds(daemon.pid()) - cpu_before;
    std::printf("  EMFILE flood: %zu connections, bslsd used %.2f s of CPU in the ~5 s held\n",
                flood.size(), cpu);
    EXPECT_LT(cpu, 1.0) << "bslsd's accept loop spins on EMFILE";
    CloseAll(&flood);
    after("EMFILE flood");
    const long rss = SettledRss(daemon.pid(), before_rss);
    std::printf("  EMFILE flood: RSS before %ld KiB, after %ld KiB\n", before_rss, rss);
    EXPECT_LE(rss, before_rss * kRssGrowth) << "memory not given back after the flood";
  }

  std::printf("bslsd after the suite: %d fds, %ld KiB\n", OpenDescriptors(daemon.pid()),
              ResidentKib(daemon.pid()));
  const auto stop = Clock::now();
  EXPECT_EQ(daemon.Terminate(seconds(30)), 0) << daemon.Log();
  const double stop_s = std::chrono::duration<double>(Clock::now() - stop).count();
  EXPECT_LE(stop_s, std::chrono::duration<double>(kShutdown).count())
      << "SIGTERM took " << stop_s << " s";
  std::error_code ec;
  if (!HasFailure()) fs::remove_all(dir, ec);
}

}  // namespace
}  // namespace bsls::processing::test
