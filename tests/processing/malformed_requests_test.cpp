// 10,000 malformed requests to each service:
// bsls-processd and bslsd run as real processes and get raw bytes through
// grpc::GenericStub on every method of their service (found in the
// descriptor, so a method added later is covered too): random bytes,
// truncated and bit-flipped valid messages, valid messages with one absurd
// field (found by reflection) or a hand-picked absurd value (huge and zero
// sizes, wrong pixel counts, bad enums, oversized strings, unknown
// calibration and capture ids, paths out of a folder, NaN figures), messages
// of another method, zero or two messages on a unary call, bidirectional
// Calibrate uploads with bad chunks, calls cancelled or abandoned mid-way,
// unknown methods and messages over the size limit.
//
// Afterwards each service must be alive and answer a valid request (no call
// may hang past its deadline; bsls-processd: no work left running or queued,
// no upload left in its scratch folder), and be back to its baseline: open
// descriptors at most kFdTolerance (4) above it, resident memory (VmRSS) at
// most kRssToleranceKib (20 MiB) above it, within a settle period of up to
// kSettle (20 s) after the last call. The baseline is taken 2 s after a
// warm-up of 1,000 requests of the same kinds (gRPC's pools, the allocator's
// arenas and the services' caches reach their working size there, so what
// remains above it is what the load kept). Under AddressSanitizer freed
// memory sits in its quarantine (256 MiB unless ASAN_OPTIONS says otherwise)
// and is not given back, so the memory bound adds that quarantine; leaks are
// then caught by LeakSanitizer when the service exits after SIGTERM, which
// must be with code 0.
//
// Statuses are tallied per method and kind of damage and printed; a status
// that says the service itself failed (UNKNOWN: an exception escaped a
// handler; DATA_LOSS; INTERNAL from the service rather than gRPC's own "could
// not parse the message") is listed and fails the test.
//
// The sanitizer stage of scripts/test.sh sends 2,000 per service (kRequests).
#include <google/protobuf/stubs/logging.h>
#include <gtest/gtest.h>
#include <signal.h>

#include <atomic>
#include <map>
#include <mutex>
#include <opencv2/imgcodecs.hpp>
#include <set>
#include <sstream>
#include <thread>

#include "bsls/processing/calibration_cache.h"
#include "bsls/testing/build_paths.h"
#include "bsls/v1/capture.grpc.pb.h"
#include "bsls/v1/processing.grpc.pb.h"
#include "daemon_process.h"
#include "processd_process.h"
#include "raw_calls.h"
#include "replica_inputs.h"

#if defined(__SANITIZE_ADDRESS__)
#define BSLS_TEST_ASAN 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define BSLS_TEST_ASAN 1
#endif
#endif

namespace bsls::processing::test {
namespace {

using Clock = std::chrono::steady_clock;
using grpc::StatusCode;

// Per service. Under the sanitizers every call costs several times as much
// (the whole load took 15 minutes there), so that stage sends 2,000 of the
// same corpus, every kind of damage on every method many times over, to find
// memory errors and leaks; the 10,000 run in the RelWithDebInfo stage.
// The warm-up brings the allocator to its steady state before the baseline
// is taken; under the sanitizers the baseline allows for their quarantine
// anyway, and a quarter of the load does.
#ifdef BSLS_TEST_ASAN
constexpr int kRequests = 2000;
constexpr int kWarmUpRequests = 500;
#else
constexpr int kRequests = 10000;
constexpr int kWarmUpRequests = 1000;
#endif
constexpr int kClientThreads = 4;
constexpr int kCallsPerChannel = 200;  // then a new connection
constexpr int kFdTolerance = 4;        // gRPC's own (timers, epoll, wakeup fds)
constexpr long kRssToleranceKib = 20 * 1024;
constexpr auto kSettle = std::chrono::seconds(20);

// The extra resident memory AddressSanitizer may keep after a load: its
// quarantine of freed blocks.
long SanitizerSlackKib() {
#ifdef BSLS_TEST_ASAN
  long quarantine_mib = 256;
  if (const char* options = std::getenv("ASAN_OPTIONS")) {
    const std::string text = options;
    if (const auto at = text.find("quarantine_size_mb="); at != std::string::npos)
      quarantine_mib = std::atol(text.c_str() + at + 19);
  }
  return (quarantine_mib + 64) * 1024;  // and 64 MiB for its allocator's own caches
#else
  return 0;
#endif
}

// The wire bytes of `message` (required fields or not).
std::string Serialized(const pb::Message& message) {
  std::string bytes;
  message.SerializePartialToString(&bytes);
  return bytes;
}

// A service's methods from its descriptor.
struct Method {
  std::string path;  // "/bsls.v1.Processing/ProcessFrame"
  std::string name;
  const pb::Descriptor* input = nullptr;
  bool client_streaming = false;
  bool server_streaming = false;
};

// Every method of `service`, in declaration order.
std::vector<Method> MethodsOf(const pb::ServiceDescriptor* service) {
  std::vector<Method> methods;
  for (int i = 0; i < service->method_count(); ++i) {
    const pb::MethodDescriptor* m = service->method(i);
    methods.push_back({"/" + service->full_name() + "/" + m->name(), m->name(), m->input_type(),
                       m->client_streaming(), m->server_streaming()});
  }
  return methods;
}

// A new message of `type` parsed from `bytes` (partial parse: whatever it holds).
std::unique_ptr<pb::Message> Parse(const pb::Descriptor* type, const std::string& bytes) {
  std::unique_ptr<pb::Message> message(
      pb::MessageFactory::generated_factory()->GetPrototype(type)->New());
  message->ParsePartialFromString(bytes);
  return message;
}

// What a request generator knows about one service: its methods, a valid
// example stream of request messages per method, and hand-picked damage per
// method (each returns a call).
struct Corpus {
  std::string service;
  std::vector<Method> methods;
  std::map<std::string, std::vector<std::string>> examples;  // by method name
  std::map<std::string, std::vector<std::function<RawCall(Rng&)>>> targeted;
  int default_deadline_ms = 20000;
  std::map<std::string, int> deadline_ms;  // by method, where another than the default
  std::size_t oversized_bytes = 0;         // one message above the receive limit
  // Bit flips go to the first 64 bytes or the last `flip_tail` bytes of a
  // message (a quarter anywhere): by method, where not the default 64 KiB.
  std::map<std::string, std::size_t> flip_tail;
};

// The i-th request of a run: method i % methods, a kind of damage at random.
RawCall MakeRequest(const Corpus& corpus, int index, Rng& rng) {
  const Method& method = corpus.methods[static_cast<std::size_t>(index) % corpus.methods.size()];
  const std::vector<std::string>& example = corpus.examples.at(method.name);
  RawCall call;
  call.method = method.path;
  const auto deadline = corpus.deadline_ms.find(method.name);
  call.deadline_ms =
      deadline != corpus.deadline_ms.end() ? deadline->second : corpus.default_deadline_ms;
  // A message over the size limit now and then (memory traffic: rarely).
  if (corpus.oversized_bytes > 0 && index % 997 == 500) {
    call.category = "oversized";
    call.messages = {std::string(corpus.oversized_bytes, '\x0a')};
    return call;
  }
  const int roll = Pick(rng, 100);
  const auto targeted = corpus.targeted.find(method.name);
  const bool has_targeted = targeted != corpus.targeted.end() && !targeted->second.empty();
  if (roll < 40 && has_targeted) {
    RawCall t = OneOf(rng, targeted->second)(rng);
    t.method = method.path;
    if (t.category.empty()) t.category = "targeted";
    t.category = "targeted:" + t.category;
    if (t.deadline_ms == RawCall{}.deadline_ms) t.deadline_ms = call.deadline_ms;
    return t;
  }
  const std::size_t which = example.empty() ? 0 : rng() % example.size();
  if (roll < 55) {
    call.category = "random bytes";
    call.messages = {RandomMessage(rng)};
    if (method.client_streaming && Pick(rng, 2) == 0) call.messages.push_back(RandomMessage(rng));
  } else if (roll < 66) {
    call.category = "truncated";
    call.messages = example;
    if (!call.messages.empty()) call.messages[which] = Truncated(call.messages[which], rng);
  } else if (roll < 74) {
    call.category = "bit flips";
    call.messages = example;
    const auto tail = corpus.flip_tail.find(method.name);
    if (!call.messages.empty())
      call.messages[which] = BitFlipped(call.messages[which], rng,
                                        tail != corpus.flip_tail.end() ? tail->second : 64 << 10);
  } else if (roll < 88) {
    call.category = "absurd field";
    call.messages = example;
    if (!call.messages.empty()) {
      std::unique_ptr<pb::Message> message = Parse(method.input, call.messages[which]);
      MutateOneField(message.get(), rng);
      call.messages[which] = Serialized(*message);
    } else {
      std::unique_ptr<pb::Message> message = Parse(method.input, "");
      MutateOneField(message.get(), rng);
      call.messages = {Serialized(*message)};
    }
  } else if (roll < 91) {
    call.category = "another method's message";
    const Method& other = OneOf(rng, corpus.methods);
    call.messages = corpus.examples.at(other.name);
  } else if (roll < 95) {
    call.category = "stream shape";
    switch (Pick(rng, 3)) {
      case 0:  // no message at all
        call.messages.clear();
        break;
      case 1:  // the example twice (two requests on a unary call)
        call.messages = example;
        call.messages.insert(call.messages.end(), example.begin(), example.end());
        break;
      default:  // no half-close: the client stalls and gives up
        call.messages = example;
        call.half_close = false;
        call.cancel_after_ms = 20 + Pick(rng, 200);
    }
  } else if (roll < 99) {
    call.category = "cancelled";
    call.messages = example;
    if (Pick(rng, 2) == 0)
      call.cancel_after_ms = Pick(rng, 60);
    else
      call.cancel_after_replies = 1;
  } else {
    call.category = "unknown method";
    call.method = OneOf<std::string>(
        rng, {"/" + corpus.service + "/NoSuchMethod", "/bsls.v1.Nothing/Get", "/", "//x//y"});
    call.messages = example;
  }
  return call;
}

// The statuses of a run, by method and by kind of damage; the suspicious ones.
struct Tally {
  std::map<std::string, std::map<int, int>> by_method;
  std::map<std::string, std::map<int, int>> by_category;
  std::map<std::string, int> suspicious;  // "method / category / code: message" -> count
  int hung = 0;
  int calls = 0;
  double slowest_s = 0;
  std::string slowest;
};

// gRPC's own INTERNAL statuses for a message that does not parse (not the service's).
bool IsGrpcParseFailure(const std::string& message) {
  return message.empty() || message.find("Failed to parse") != std::string::npos ||
         message.find("No payload") != std::string::npos ||
         message.find("Error parsing") != std::string::npos ||
         message.find("Couldn't initialize byte buffer reader") != std::string::npos;
}

// Runs `count` requests (generator seed `seed`) on kClientThreads threads,
// each on connections of its own that it replaces every kCallsPerChannel
// calls; every channel is closed when this returns.
Tally RunLoad(const Corpus& corpus, int count, std::uint64_t seed,
              const std::function<std::shared_ptr<grpc::Channel>(int)>& open_channel) {
  Tally tally;
  std::mutex mutex;
  std::atomic<int> next{0}, channels{0};
  std::vector<std::thread> threads;
  for (int t = 0; t < kClientThreads; ++t)
    threads.emplace_back([&] {
      std::shared_ptr<grpc::Channel> channel;
      std::unique_ptr<grpc::GenericStub> stub;
      int on_channel = kCallsPerChannel;
      for (int i; (i = next++) < count;) {
        if (on_channel++ >= kCallsPerChannel) {
          stub.reset();
          channel = open_channel(channels++);
          stub = std::make_unique<grpc::GenericStub>(channel);
          on_channel = 1;
        }
        Rng rng(seed * 1000003u + static_cast<std::uint64_t>(i));
        const RawCall call = MakeRequest(corpus, i, rng);
        const RawOutcome out = SendRaw(*stub, call);
        std::string method = call.method.substr(call.method.rfind('/') + 1);
        std::lock_guard lock(mutex);
        ++tally.calls;
        ++tally.by_method[method][out.code];
        ++tally.by_category[call.category][out.code];
        if (out.hung) ++tally.hung;
        if (out.seconds > tally.slowest_s) {
          tally.slowest_s = out.seconds;
          tally.slowest = method + " / " + call.category;
        }
        const bool suspicious =
            out.code == StatusCode::UNKNOWN || out.code == StatusCode::DATA_LOSS ||
            (out.code == StatusCode::INTERNAL && !IsGrpcParseFailure(out.message));
        if (suspicious)
          ++tally.suspicious[method + " / " + call.category + " / " + std::to_string(out.code) +
                             ": " + out.message.substr(0, 200)];
      }
    });
  for (std::thread& t : threads) t.join();
  return tally;
}

// "INVALID_ARGUMENT" for 3 and so on.
std::string CodeName(int code) {
  static const char* names[] = {"OK",
                                "CANCELLED",
                                "UNKNOWN",
                                "INVALID_ARGUMENT",
                                "DEADLINE_EXCEEDED",
                                "NOT_FOUND",
                                "ALREADY_EXISTS",
                                "PERMISSION_DENIED",
                                "RESOURCE_EXHAUSTED",
                                "FAILED_PRECONDITION",
                                "ABORTED",
                                "OUT_OF_RANGE",
                                "UNIMPLEMENTED",
                                "INTERNAL",
                                "UNAVAILABLE",
                                "DATA_LOSS",
                                "UNAUTHENTICATED"};
  return code >= 0 && code <= 16 ? names[code] : std::to_string(code);
}

// Prints the tally of `who` on stdout (it lands in the CTest log).
void Print(const std::string& who, const Tally& tally) {
  std::ostringstream out;
  out << who << ": " << tally.calls << " calls, " << tally.hung << " hung, slowest "
      << tally.slowest_s << " s (" << tally.slowest << ")\n";
  for (const auto* table : {&tally.by_method, &tally.by_category})
    for (const auto& [key, codes] : *table) {
      out << "  " << key << ":";
      for (const auto& [code, n] : codes) out << " " << CodeName(code) << " " << n;
      out << "\n";
    }
  for (const auto& [what, n] : tally.suspicious)
    out << "  SUSPICIOUS x" << n << " " << what << "\n";
  std::printf("%s", out.str().c_str());
  std::fflush(stdout);
}

// Open descriptors and resident memory of a process.
struct Footprint {
  int fds = 0;
  long rss_kib = 0;
};

// The footprint of `pid` now.
Footprint FootprintOf(pid_t pid) { return {OpenDescriptors(pid), ResidentKib(pid)}; }

// Waits up to kSettle for `pid` to come back within the tolerances of
// `baseline`; the footprint it reached.
Footprint SettleTo(pid_t pid, const Footprint& baseline) {
  const auto until = Clock::now() + kSettle;
  Footprint now = FootprintOf(pid);
  while (Clock::now() < until &&
         (now.fds > baseline.fds + kFdTolerance ||
          now.rss_kib > baseline.rss_kib + kRssToleranceKib + SanitizerSlackKib())) {
    std::this_thread::sleep_for(std::chrono::milliseconds(250));
    now = FootprintOf(pid);
  }
  return now;
}

// Waits for the process `name` (`pid`) to settle after the load, prints its
// footprints (fresh, after the warm-up, after the load) and the phases'
// times, and expects it back within the tolerances of `baseline`.
void ExpectBackToBaseline(const char* name, pid_t pid, const Footprint& fresh,
                          const Footprint& baseline, double warm_s, double load_s) {
  const Footprint after = SettleTo(pid, baseline);
  const long rss_tolerance = kRssToleranceKib + SanitizerSlackKib();
  std::printf(
      "%s: fds fresh %d, baseline %d, after %d; RSS fresh %ld KiB, baseline %ld KiB, after %ld "
      "KiB (tolerance %ld KiB); warm-up %.1f s, load %.1f s\n",
      name, fresh.fds, baseline.fds, after.fds, fresh.rss_kib, baseline.rss_kib, after.rss_kib,
      rss_tolerance, warm_s, load_s);
  EXPECT_LE(after.fds, baseline.fds + kFdTolerance) << name;
  EXPECT_LE(after.rss_kib, baseline.rss_kib + rss_tolerance)
      << name << " kept more resident memory than its baseline after the load";
}

// A channel of its own (a new connection, not a shared subchannel).
std::shared_ptr<grpc::Channel> FreshChannel(const std::string& target, int n) {
  grpc::ChannelArguments args;
  args.SetInt("bsls.test.connection", n);
  args.SetMaxReceiveMessageSize(16 << 20);
  args.SetMaxSendMessageSize(64 << 20);
  return grpc::CreateCustomChannel(target, grpc::InsecureChannelCredentials(), args);
}

// Protobuf's log handler for this test: only fatal messages (the absurd
// messages make protobuf complain about non-UTF-8 strings thousands of times).
void QuietProtobuf(google::protobuf::LogLevel level, const char*, int, const std::string& text) {
  if (level >= google::protobuf::LOGLEVEL_FATAL) std::fprintf(stderr, "%s\n", text.c_str());
}

// ---------------------------------------------------------------------------
// bsls-processd

// A Calibrate message carrying a manifest.
std::string ManifestMessage(const std::string& yaml, const std::string& tag = "") {
  v1::CalibrateRequest request;
  request.mutable_manifest()->set_yaml(yaml);
  request.mutable_manifest()->set_request_tag(tag);
  return Serialized(request);
}

// A Calibrate message carrying one chunk of a file.
std::string ChunkMessage(const std::string& path, std::uint64_t offset, const std::string& data,
                         bool last) {
  v1::CalibrateRequest request;
  v1::FileChunk* chunk = request.mutable_file();
  chunk->set_path(path);
  chunk->set_offset(offset);
  chunk->set_data(data);
  chunk->set_last(last);
  return Serialized(request);
}

// A manifest of a left session whose images are named as given.
std::string ManifestYaml(const std::vector<std::string>& camera,
                         const std::vector<std::string>& screen) {
  std::string yaml =
      "side: left\ntarget: {rows: 8, cols: 8, pitch_mm: 6.5, square_mm: 4}\ncamera_views:\n";
  for (std::size_t i = 0; i < camera.size(); ++i)
    yaml += "  - {image: \"" + camera[i] + "\", z_mm: " + std::to_string(50 * i) + "}\n";
  yaml += "screen_views:\n";
  for (std::size_t i = 0; i < screen.size(); ++i)
    yaml += "  - {image: \"" + screen[i] + "\", z_mm: " + std::to_string(60 * i) + "}\n";
  return yaml + "pattern: {lines: 20, rows: 24}\n";
}

// A calibration file with its first occurrence of `key: ...` given `value`.
std::string WithValue(std::string yaml, const std::string& key, const std::string& value) {
  const std::size_t at = yaml.find(key + ":");
  if (at == std::string::npos) return yaml;
  const std::size_t start = at + key.size() + 1;
  const std::size_t end = yaml.find_first_of(",}\n", start);
  return yaml.replace(start, end - start, " " + value);
}

// bsls-processd's methods with valid examples and hand-picked damage;
// `binary_ply` / `ascii_ply`: a joined face surface as the service wrote it.
Corpus ProcessdCorpus(const SessionInputs& inputs, const std::string& binary_ply,
                      const std::string& ascii_ply) {
  Corpus c;
  c.service = "bsls.v1.Processing";
  c.methods =
      MethodsOf(pb::DescriptorPool::generated_pool()->FindServiceByName("bsls.v1.Processing"));
  c.default_deadline_ms = 20000;
  // A real session under AddressSanitizer, queued behind others.
  for (const char* work : {"ProcessFrame", "ReconstructSession", "Calibrate", "Measure"})
    c.deadline_ms[work] = 300000;
  c.oversized_bytes = (40u << 20) + 1024;

  const std::string& left_yaml = inputs.left_calibration;
  const std::string& right_yaml = inputs.right_calibration;
  const std::string left_id = CalibrationCache::IdOf(left_yaml);
  cv::Mat noise(64, 64, CV_8UC1);
  cv::randu(noise, 0, 256);
  v1::ProcessFrameRequest small;
  contract::ToFrameMessage(noise, small.mutable_frame());
  small.set_side(v1::SIDE_LEFT);
  v1::ProcessFrameRequest face;
  contract::ToFrameMessage(inputs.left_face, face.mutable_frame());
  face.set_side(v1::SIDE_LEFT);
  *face.mutable_calibration() = ProcessingClient::Inline(left_yaml);
  face.set_want_surface(true);
  const v1::ReconstructSessionRequest session = SessionRequestOf(inputs);
  {  // flips in the calibrations rather than in the pixels (which would make valid sessions)
    v1::ReconstructSessionRequest rest = session;
    rest.clear_left();
    rest.clear_right();
    c.flip_tail["ReconstructSession"] = rest.ByteSizeLong();
  }

  // An upload: a manifest naming six images (the fewest views a calibration
  // takes), then six blank 512 x 512 PNGs (readable, the right size, no
  // target in them).
  const std::vector<std::string> camera = {"t0.png", "t1.png", "t2.png"};
  const std::vector<std::string> screen = {"s0.png", "s1.png", "s2.png"};
  std::vector<unsigned char> png;
  cv::imencode(".png", cv::Mat(512, 512, CV_8UC1, cv::Scalar(200)), png);
  const std::string blank(png.begin(), png.end());
  std::vector<std::string> upload = {ManifestMessage(ManifestYaml(camera, screen), "robust")};
  for (const auto* names : {&camera, &screen})
    for (const std::string& name : *names) upload.push_back(ChunkMessage(name, 0, blank, true));

  c.examples["ProcessFrame"] = {Serialized(small)};
  c.examples["ReconstructSession"] = {Serialized(session)};
  c.examples["Calibrate"] = upload;
  v1::PutCalibrationRequest put;
  put.set_yaml(left_yaml);
  c.examples["PutCalibration"] = {Serialized(put)};
  v1::GetCalibrationRequest get;
  get.set_id(left_id);
  c.examples["GetCalibration"] = {Serialized(get)};
  // Measure (when the service has it): a height and an area on the face.
  v1::MeasureRequest measure;
  measure.set_surface_ply(binary_ply);
  {
    v1::PointXY* h = measure.mutable_measurements()->add_heights();
    h->set_x(0);
    h->set_y(-60);
    v1::Polygon* area = measure.mutable_measurements()->add_areas();
    for (auto [x, y] : {std::pair{-10.0, -50.0}, {10.0, -50.0}, {10.0, -70.0}, {-10.0, -70.0}}) {
      v1::PointXY* p = area->add_points();
      p->set_x(x);
      p->set_y(y);
    }
  }
  c.examples["Measure"] = {Serialized(measure)};
  for (const Method& m : c.methods)
    if (!c.examples.count(m.name)) c.examples[m.name] = {""};  // a method added later

  // Absurd frames (applied to ProcessFrame's frame and to either side of a session).
  const std::vector<std::function<void(v1::Frame*, Rng&)>> frame_damage = {
      [](v1::Frame* f, Rng&) { f->set_width(0); },
      [](v1::Frame* f, Rng&) { f->set_height(0); },
      [](v1::Frame* f, Rng&) { f->set_width(4097); },
      [](v1::Frame* f, Rng&) { f->set_height(std::numeric_limits<std::uint32_t>::max()); },
      [](v1::Frame* f, Rng&) {  // claims 4096 x 4096, brings one byte
        f->set_width(4096);
        f->set_height(4096);
        f->set_stride(4096);
        f->set_pixels("x");
      },
      [](v1::Frame* f, Rng&) { f->set_stride(f->width() - 1); },
      [](v1::Frame* f, Rng&) { f->set_stride(std::numeric_limits<std::uint32_t>::max()); },
      [](v1::Frame* f, Rng&) { f->set_stride(0); },
      [](v1::Frame* f, Rng&) { f->mutable_pixels()->pop_back(); },
      [](v1::Frame* f, Rng&) { f->mutable_pixels()->push_back('\0'); },
      [](v1::Frame* f, Rng&) { f->clear_pixels(); },
      [](v1::Frame* f, Rng&) { f->Clear(); },
      [](v1::Frame* f, Rng&) {  // 1 x 1
        f->set_width(1);
        f->set_height(1);
        f->set_stride(1);
        f->set_pixels("\x80");
      },
      [](v1::Frame* f, Rng& rng) {  // noise of the right size: nothing to decode
        *f->mutable_pixels() = RandomBytes(rng, f->pixels().size());
      },
      [](v1::Frame* f, Rng&) {  // 256 x 256 grey: another size than the calibration
        f->set_width(256);
        f->set_height(256);
        f->set_stride(256);
        f->set_pixels(std::string(256 * 256, '\x40'));
      },
  };
  // Absurd calibrations.
  const std::vector<std::function<v1::CalibrationSource(Rng&)>> calibration_damage = {
      [](Rng&) { return v1::CalibrationSource(); },
      [](Rng&) {
        v1::CalibrationSource s;
        s.set_id("");
        return s;
      },
      [](Rng&) {
        v1::CalibrationSource s;
        s.set_id("sha256:" + std::string(64, 'a'));  // unknown
        return s;
      },
      [](Rng&) {
        v1::CalibrationSource s;
        s.set_id("sha256:");
        return s;
      },
      [](Rng&) {
        v1::CalibrationSource s;
        s.set_id(std::string(1 << 20, 'i'));
        return s;
      },
      [](Rng&) {
        v1::CalibrationSource s;
        s.set_yaml("");
        return s;
      },
      [](Rng&) {
        v1::CalibrationSource s;
        s.set_yaml("format: [unclosed");
        return s;
      },
      [](Rng&) {
        v1::CalibrationSource s;
        s.set_yaml(std::string(100000, '[') + std::string(100000, ']'));  // nesting
        return s;
      },
      [](Rng&) {  // aliases of aliases
        std::string yaml = "a0: &a0 [x, x, x, x, x, x, x, x]\n";
        for (int i = 1; i < 30; ++i)
          yaml += "a" + std::to_string(i) + ": &a" + std::to_string(i) + " [*a" +
                  std::to_string(i - 1) + ", *a" + std::to_string(i - 1) + ", *a" +
                  std::to_string(i - 1) + "]\n";
        v1::CalibrationSource s;
        s.set_yaml(yaml);
        return s;
      },
      [left_yaml](Rng& rng) {
        v1::CalibrationSource s;
        s.set_yaml(Truncated(left_yaml, rng));
        return s;
      },
      [left_yaml](Rng& rng) {
        v1::CalibrationSource s;
        s.set_yaml(WithValue(left_yaml,
                             OneOf<std::string>(rng, {"width", "height", "fx", "fy", "cx", "k1",
                                                      "z_mm", "format_version"}),
                             OneOf<std::string>(rng, {".nan", ".inf", "-.inf", "1e309", "-5", "0",
                                                      "100000", "4294967296", "\"text\"", "[]"})));
        return s;
      },
      [right_yaml](Rng&) {  // the other side's
        v1::CalibrationSource s;
        s.set_yaml(right_yaml);
        return s;
      },
      [](Rng&) {
        v1::CalibrationSource s;
        s.set_yaml(std::string((4 << 20) + 1, '#'));
        return s;
      },
      [](Rng& rng) {
        v1::CalibrationSource s;
        s.set_yaml(RandomBytes(rng, 10000));
        return s;
      },
  };

  auto work_call = [](const pb::Message& request, const std::string& category) {
    RawCall call;
    call.messages = {Serialized(request)};
    call.category = category;
    return call;
  };
  auto& frame = c.targeted["ProcessFrame"];
  frame.push_back([=](Rng& rng) {
    v1::ProcessFrameRequest r = Pick(rng, 4) == 0 ? face : small;
    OneOf(rng, frame_damage)(r.mutable_frame(), rng);
    return work_call(r, "frame");
  });
  frame.push_back([=](Rng& rng) {
    v1::ProcessFrameRequest r = face;
    *r.mutable_calibration() = OneOf(rng, calibration_damage)(rng);
    return work_call(r, "calibration");
  });
  frame.push_back([=](Rng& rng) {
    v1::ProcessFrameRequest r = small;
    r.set_side(static_cast<v1::Side>(OneOf<int>(rng, {0, 3, 99, -1})));
    r.mutable_decode()->set_method(
        static_cast<v1::DecodeOptions::Method>(OneOf<int>(rng, {0, 77, -2})));
    r.mutable_surface()->set_plane_model(
        static_cast<v1::SurfaceOptions::PlaneModel>(OneOf<int>(rng, {0, 5, -3})));
    return work_call(r, "enums");
  });
  frame.push_back([=](Rng& rng) {
    v1::ProcessFrameRequest r = small;
    r.set_want_surface(true);  // without a calibration
    r.set_request_tag(
        OneOf<std::string>(rng, {std::string(257, 't'), std::string(1 << 20, 't'), ""}));
    return work_call(r, "want_surface, tag");
  });
  frame.push_back([=](Rng& rng) {  // the right calibration for a left frame
    v1::ProcessFrameRequest r = face;
    *r.mutable_calibration() = ProcessingClient::Inline(right_yaml);
    r.set_want_overlay(Pick(rng, 2) == 1);
    return work_call(r, "other side's calibration");
  });

  auto& recon = c.targeted["ReconstructSession"];
  recon.push_back([=](Rng& rng) {
    v1::ReconstructSessionRequest r = session;
    OneOf(rng, frame_damage)(Pick(rng, 2) ? r.mutable_left() : r.mutable_right(), rng);
    return work_call(r, "frame");
  });
  recon.push_back([=](Rng& rng) {
    v1::ReconstructSessionRequest r = session;
    *(Pick(rng, 2) ? r.mutable_left_calibration() : r.mutable_right_calibration()) =
        OneOf(rng, calibration_damage)(rng);
    return work_call(r, "calibration");
  });
  recon.push_back([=](Rng& rng) {  // swapped, or one side's for both
    v1::ReconstructSessionRequest r = session;
    if (Pick(rng, 2))
      std::swap(*r.mutable_left_calibration(), *r.mutable_right_calibration());
    else
      *r.mutable_right_calibration() = r.left_calibration();
    return work_call(r, "calibrations swapped");
  });
  recon.push_back([=](Rng& rng) {  // absurd figures to measure: the whole chain runs first
    v1::ReconstructSessionRequest r = session;
    v1::MeasurementPlan* plan = r.mutable_measurements();
    const double kNan = std::numeric_limits<double>::quiet_NaN();
    const double kInf = std::numeric_limits<double>::infinity();
    const std::vector<double> values = {kNan, kInf, -kInf, 1e300, -1e300, 0.0, 5e-324};
    auto point = [&](v1::PointXY* p, bool absurd) {
      p->set_x(absurd ? OneOf(rng, values) : -10.0 + Pick(rng, 20));
      p->set_y(absurd ? OneOf(rng, values) : -70.0 + Pick(rng, 20));
    };
    switch (Pick(rng, 9)) {
      case 0:
        for (int i = 0; i < 101; ++i) point(plan->add_heights(), false);
        break;
      case 1:
        for (int i = 0, n = OneOf<int>(rng, {0, 1, 3}); i < n; ++i)
          point(plan->add_distances()->add_points(), false);
        break;
      case 2:
        point(plan->add_heights(), true);
        break;
      case 3: {
        v1::Polygon* d = plan->add_distances();
        point(d->add_points(), true);
        point(d->add_points(), Pick(rng, 2));
        break;
      }
      case 4: {  // polygons of 2 points, or absurd corners
        v1::Polygon* a = Pick(rng, 2) ? plan->add_areas() : plan->add_lesions();
        for (int i = 0, n = OneOf<int>(rng, {0, 2, 4}); i < n; ++i) point(a->add_points(), n == 4);
        break;
      }
      case 5: {  // a polygon of 10,000 corners
        v1::Polygon* a = Pick(rng, 2) ? plan->add_areas() : plan->add_lesions();
        for (int i = 0; i < 10000; ++i) {
          v1::PointXY* p = a->add_points();
          p->set_x(20 * std::cos(i * 0.00062832 * 7));
          p->set_y(-60 + 20 * std::sin(i * 0.00062832 * 13));
        }
        break;
      }
      case 6:
        plan->set_ring_mm(OneOf(rng, values));
        point(plan->add_lesions()->add_points(), false);
        break;
      case 7: {  // a lesion with an absurd ring and reference
        plan->set_ring_mm(OneOf<double>(rng, {-1.0, 1e300, 1e-300}));
        plan->set_reference(static_cast<v1::MeasurementPlan::Reference>(OneOf<int>(rng, {42, -1})));
        v1::Polygon* l = plan->add_lesions();
        for (auto [x, y] :
             {std::pair{-10.0, -50.0}, {10.0, -50.0}, {10.0, -70.0}, {-10.0, -70.0}}) {
          v1::PointXY* p = l->add_points();
          p->set_x(x);
          p->set_y(y);
        }
        break;
      }
      default:  // far off the face
        for (int i = 0; i < 4; ++i) {
          v1::PointXY* p = plan->add_areas()->add_points();
          p->set_x(1e6 + i);
          p->set_y(1e6 - i);
        }
    }
    return work_call(r, "measurements");
  });
  recon.push_back([=](Rng& rng) {
    v1::ReconstructSessionRequest r = session;
    r.set_join(static_cast<v1::ReconstructSessionRequest::Join>(OneOf<int>(rng, {1000, -1})));
    r.set_request_tag(OneOf<std::string>(rng, {std::string(257, 't'), std::string(1 << 20, 't')}));
    return work_call(r, "join, tag");
  });

  // Measure: damaged surfaces (header counts, formats, bodies, indices) and plans.
  const std::vector<std::function<std::string(Rng&)>> ply_damage = {
      [=](Rng& rng) {  // absurd element counts
        const std::string element = Pick(rng, 2) ? "element vertex " : "element face ";
        std::string ply = Pick(rng, 2) ? binary_ply : ascii_ply;
        const std::size_t at = ply.find(element);
        const std::size_t end = ply.find('\n', at);
        return ply.replace(at + element.size(), end - at - element.size(),
                           OneOf<std::string>(rng, {"4000000000", "18446744073709551615", "-1", "0",
                                                    "1e9", "99999999999999999999999", ""}));
      },
      [=](Rng& rng) {  // another format line
        std::string ply = binary_ply;
        const std::size_t at = ply.find("format ");
        const std::size_t end = ply.find('\n', at);
        return ply.replace(
            at, end - at,
            OneOf<std::string>(rng, {"format binary_big_endian 1.0", "format ascii 2.0",
                                     "format binary_little_endian", "format x 1.0"}));
      },
      [=](Rng& rng) {  // header lines changed or missing
        std::string ply = Pick(rng, 2) ? binary_ply : ascii_ply;
        switch (Pick(rng, 5)) {
          case 0:
            return ply.replace(ply.find("end_header"), 10, "end_headr");
          case 1:
            return ply.replace(ply.find("property list"), 13, "property list float");
          case 2:
            return ply.insert(ply.find("element face"),
                              "element bogus 1000000\nproperty double q\n");
          case 3:
            return ply.insert(4, std::string(8 << 20, '\n'));  // 8 MiB of blank header lines
          default:
            return ply.substr(0, ply.find("end_header") + 11);  // a header without a body
        }
      },
      [=](Rng& rng) {  // the body truncated or replaced by noise
        std::string ply = Pick(rng, 2) ? binary_ply : ascii_ply;
        const std::size_t body = ply.find("end_header") + 11;
        if (Pick(rng, 2)) return ply.substr(0, body + rng() % (ply.size() - body));
        return ply.substr(0, body) + RandomBytes(rng, ply.size() - body);
      },
      [=](Rng& rng) {  // ASCII numbers that are not numbers, indices out of range
        std::string ply = ascii_ply;
        const std::size_t body = ply.find("end_header") + 11;
        const std::string bad = OneOf<std::string>(
            rng, {"nan", "inf", "-inf", "1e400", "x", "-1", "4294967295", "255", "99999999"});
        for (int i = 0; i < 5; ++i) {
          std::size_t at = body + rng() % (ply.size() - body);
          at = ply.find(' ', at);
          if (at == std::string::npos) break;
          const std::size_t end = ply.find_first_of(" \n", at + 1);
          ply.replace(at + 1, end - at - 1, bad);
        }
        return ply;
      },
      [](Rng& rng) {
        return OneOf<std::string>(rng, {"", "ply\n", "ply\nformat ascii 1.0\nend_header\n"});
      },
  };
  auto& measure_cases = c.targeted["Measure"];
  measure_cases.push_back([=](Rng& rng) {
    v1::MeasureRequest r = measure;
    r.set_surface_ply(OneOf(rng, ply_damage)(rng));
    return work_call(r, "surface");
  });
  measure_cases.push_back([=](Rng& rng) {  // a baseline scan: damaged, or noise, or the surface
    v1::MeasureRequest r = measure;
    v1::Polygon* l = r.mutable_measurements()->add_lesions();
    for (auto [x, y] : {std::pair{-10.0, -50.0}, {10.0, -50.0}, {10.0, -70.0}, {-10.0, -70.0}}) {
      v1::PointXY* p = l->add_points();
      p->set_x(x);
      p->set_y(y);
    }
    switch (Pick(rng, 3)) {
      case 0:
        r.set_baseline_ply(OneOf(rng, ply_damage)(rng));
        break;
      case 1:
        r.set_baseline_ply(RandomBytes(rng, 1 + Pick(rng, 4096)));
        break;
      default:
        r.set_baseline_ply(ascii_ply);
        r.set_baseline_shares_frame(Pick(rng, 2) == 1);
    }
    return work_call(r, "baseline");
  });
  measure_cases.push_back([=](Rng& rng) {  // absurd plans on a good surface
    v1::MeasureRequest r = measure;
    v1::MeasurementPlan* plan = r.mutable_measurements();
    const double kNan = std::numeric_limits<double>::quiet_NaN();
    switch (Pick(rng, 5)) {
      case 0:
        plan->Clear();
        break;
      case 1:
        for (int i = 0; i < 101; ++i) plan->add_heights()->set_x(i);
        break;
      case 2:
        plan->mutable_heights(0)->set_x(OneOf<double>(rng, {kNan, 1e300, -1e300}));
        break;
      case 3:
        plan->set_ring_mm(OneOf<double>(rng, {kNan, -1.0, 1e300}));
        *plan->add_lesions() = plan->areas(0);
        break;
      default: {
        v1::Polygon* a = plan->add_lesions();
        for (int i = 0; i < 10000; ++i) {
          v1::PointXY* p = a->add_points();
          p->set_x(20 * std::cos(i * 0.0044));
          p->set_y(-60 + 20 * std::sin(i * 0.0082));
        }
      }
    }
    r.set_request_tag(Pick(rng, 4) ? "" : std::string(257, 't'));
    return work_call(r, "plan");
  });

  auto& put_cases = c.targeted["PutCalibration"];
  put_cases.push_back([=](Rng& rng) {
    const v1::CalibrationSource s = OneOf(rng, calibration_damage)(rng);
    v1::PutCalibrationRequest r;
    r.set_yaml(s.has_yaml() ? s.yaml() : s.id());
    return work_call(r, "calibration file");
  });
  auto& get_cases = c.targeted["GetCalibration"];
  get_cases.push_back([=](Rng& rng) {
    v1::GetCalibrationRequest r;
    r.set_id(OneOf<std::string>(
        rng, {"", "sha256:", "sha256:" + std::string(64, '0'), std::string(1 << 20, 'i'),
              std::string(1, '\0'), "sha256:../x", "SHA256:" + std::string(64, 'A')}));
    return work_call(r, "id");
  });

  // Calibrate: bad uploads, each a whole stream.
  const std::string manifest = upload[0];
  auto upload_call = [](std::vector<std::string> messages, const std::string& category) {
    RawCall call;
    call.messages = std::move(messages);
    call.category = category;
    return call;
  };
  auto& cal = c.targeted["Calibrate"];
  cal.push_back([=](Rng& rng) {
    switch (Pick(rng, 5)) {
      case 0:
        return upload_call({}, "no manifest");
      case 1:
        return upload_call({ChunkMessage("t0.png", 0, blank, true)}, "file first");
      case 2:
        return upload_call({ManifestMessage(std::string((1 << 20) + 1, '#'))}, "huge manifest");
      case 3:
        return upload_call({ManifestMessage("x", std::string(257, 't'))}, "long tag");
      default:
        return upload_call({ManifestMessage(OneOf<std::string>(
                               rng, {"", "[", "side: up", std::string(50000, '[') + "x",
                                     "side: left\ncamera_views: 7\n"}))},
                           "bad manifest");
    }
  });
  cal.push_back([=](Rng& rng) {
    const std::string path =
        OneOf<std::string>(rng, {"", "../t0.png", "/etc/passwd", "a/../../b.png", "./t0.png",
                                 "a//b.png", "a/", std::string(300, 'p'), "manifest.yaml",
                                 std::string("a\0b", 3), "..", ".", "\xff\xfe.png"});
    return upload_call({manifest, ChunkMessage(path, 0, "1234", true)}, "bad path");
  });
  cal.push_back([=](Rng& rng) {
    std::vector<std::string> m = {manifest};
    switch (Pick(rng, 9)) {
      case 0:  // skips ahead
        m.push_back(ChunkMessage("t0.png", 5, "1234", true));
        break;
      case 1:  // goes back
        m.push_back(ChunkMessage("t0.png", 0, "1234", false));
        m.push_back(ChunkMessage("t0.png", 0, "1234", true));
        break;
      case 2:
        m.push_back(ChunkMessage("t0.png", std::numeric_limits<std::uint64_t>::max(), "1", true));
        break;
      case 3:  // sent twice
        m.push_back(ChunkMessage("t0.png", 0, blank, true));
        m.push_back(ChunkMessage("t0.png", 0, blank, true));
        break;
      case 4:  // a second file begun before the first is complete
        m.push_back(ChunkMessage("t0.png", 0, "12", false));
        m.push_back(ChunkMessage("t1.png", 0, "12", true));
        break;
      case 5:  // a chunk above 4 MiB
        m.push_back(ChunkMessage("t0.png", 0, std::string((4 << 20) + 1, 'c'), true));
        break;
      case 6:  // a second manifest
        m.push_back(manifest);
        break;
      case 7:  // a file, then a folder of the same name (and the reverse)
        if (Pick(rng, 2)) {
          m.push_back(ChunkMessage("d", 0, "1", true));
          m.push_back(ChunkMessage("d/e.png", 0, "1", true));
        } else {
          m.push_back(ChunkMessage("d/e.png", 0, "1", true));
          m.push_back(ChunkMessage("d", 0, "1", true));
        }
        break;
      default:  // the upload ends in the middle of a file
        m.push_back(ChunkMessage("t0.png", 0, "1234", false));
    }
    return upload_call(m, "bad chunks");
  });
  cal.push_back([=](Rng& rng) {  // above max_upload_bytes (2 MiB), or 257 files
    std::vector<std::string> m = {manifest};
    if (Pick(rng, 2)) {
      for (int i = 0; i < 3; ++i)
        m.push_back(ChunkMessage("big.png", static_cast<std::uint64_t>(i) << 20,
                                 std::string(1 << 20, 'b'), i == 2));
    } else {
      for (int i = 0; i < 257; ++i)
        m.push_back(ChunkMessage("f" + std::to_string(i), 0, "1", true));
    }
    return upload_call(m, "upload limits");
  });
  cal.push_back([=](Rng& rng) {  // the manifest names files outside the upload
    const std::vector<std::string> outside = {"/etc/passwd", "/etc/hostname",
                                              "../../../../etc/passwd", "/proc/self/status",
                                              "/nonexistent/x.png"};
    std::vector<std::string> m = {ManifestMessage(
        ManifestYaml({OneOf(rng, outside), "t1.png", "t2.png"}, {"s0.png", "s1.png"}))};
    for (const char* name : {"t1.png", "t2.png", "s0.png", "s1.png"})
      m.push_back(ChunkMessage(name, 0, blank, true));
    return upload_call(m, "manifest names files outside the upload");
  });
  cal.push_back([=](Rng& rng) {  // junk images of the right names
    std::vector<std::string> m = {manifest};
    for (const auto* names : {&camera, &screen})
      for (const std::string& name : *names)
        m.push_back(ChunkMessage(name, 0, RandomBytes(rng, 1 + Pick(rng, 4096)), true));
    return upload_call(m, "junk images");
  });
  cal.push_back([=](Rng& rng) {  // abandoned: no half-close, cancelled mid-upload
    RawCall call = upload_call(upload, "abandoned upload");
    call.messages.resize(1 + static_cast<std::size_t>(Pick(rng, static_cast<int>(upload.size()))));
    call.half_close = false;
    call.cancel_after_ms = 10 + Pick(rng, 150);
    return call;
  });
  return c;
}

// A valid session through ProcessingClient: OK with a Result.
::testing::AssertionResult AnswersASession(const ProcessdProcess& replica,
                                           const v1::ReconstructSessionRequest& request) {
  ClientOptions options;
  options.target = replica.address();
  options.attempts = 1;
  options.timeout = std::chrono::minutes(5);
  ProcessingClient client(OpenProcessingChannel(options), options);
  const WorkOutcome out = client.ReconstructSession(request);
  if (!out.status.ok())
    return ::testing::AssertionFailure()
           << out.status.error_code() << " " << out.status.error_message();
  if (out.result.replica() != replica.name() || out.result.sides_size() != 2)
    return ::testing::AssertionFailure() << "no proper Result: " << out.result.ShortDebugString();
  return ::testing::AssertionSuccess();
}

// GetServerInfo of `replica` (empty on failure).
v1::ServerInfo InfoOf(const ProcessdProcess& replica) {
  auto stub = v1::Processing::NewStub(FreshChannel(replica.address(), -1));
  grpc::ClientContext context;
  context.set_deadline(std::chrono::system_clock::now() + std::chrono::seconds(20));
  v1::ServerInfo info;
  stub->GetServerInfo(&context, {}, &info);
  return info;
}

// bsls-processd takes 10,000 malformed requests and comes back to its
// baseline, alive, idle and answering.
TEST(MalformedRequests, ProcessdSurvivesTenThousand) {
  google::protobuf::SetLogHandler(&QuietProtobuf);
  const SessionInputs& inputs = LightSessionInputs();
  const v1::ReconstructSessionRequest session = SessionRequestOf(inputs);
  const fs::path folder = MakeTempFolder("bsls_malformed_processd_");
  const fs::path scratch = folder / "scratch";
  fs::create_directories(scratch);
  ProcessdProcess replica(bsls::testing::ProcessdPath(), folder, "robust", 2,
                          {"--set", "scratch_dir=" + scratch.string(), "--set",
                           "max_upload_bytes=2097152", "--set", "log_level=warn"});
  ASSERT_TRUE(replica.ready()) << replica.Log();
  const auto open = [&](int n) { return FreshChannel(replica.address(), n); };
  ASSERT_TRUE(AnswersASession(replica, session));
  // The joined surface of the session, binary and ASCII, to damage for Measure.
  std::string surfaces[2];
  for (int ascii = 0; ascii < 2; ++ascii) {
    ClientOptions options;
    options.target = replica.address();
    options.timeout = std::chrono::minutes(5);
    ProcessingClient client(OpenProcessingChannel(options), options);
    v1::ReconstructSessionRequest request = session;
    request.mutable_surface()->set_ascii_ply(ascii == 1);
    const WorkOutcome out = client.ReconstructSession(request);
    ASSERT_TRUE(out.status.ok()) << out.status.error_message();
    surfaces[ascii] = out.files.at("surface.ply");
  }
  const Corpus corpus = ProcessdCorpus(inputs, surfaces[0], surfaces[1]);
  const Footprint fresh = FootprintOf(replica.pid());
  const auto warm_start = Clock::now();
  RunLoad(corpus, kWarmUpRequests, 1, open);
  ASSERT_FALSE(replica.exited()) << "bsls-processd died in the warm-up: signal " << replica.signal()
                                 << "\n"
                                 << replica.Log();
  ASSERT_TRUE(AnswersASession(replica, session)) << replica.Log();
  std::this_thread::sleep_for(std::chrono::seconds(2));
  const Footprint baseline = FootprintOf(replica.pid());
  const double warm_s = std::chrono::duration<double>(Clock::now() - warm_start).count();

  const auto load_start = Clock::now();
  const Tally tally = RunLoad(corpus, kRequests, 2, open);
  const double load_s = std::chrono::duration<double>(Clock::now() - load_start).count();
  Print("bsls-processd", tally);

  // Alive, answering, and nothing left running or queued.
  ASSERT_FALSE(replica.exited()) << "bsls-processd died: signal " << replica.signal() << "\n"
                                 << replica.Log();
  EXPECT_TRUE(AnswersASession(replica, session));
  v1::ServerInfo info = InfoOf(replica);
  for (int i = 0; i < 100 && info.busy() + info.waiting() > 0; ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
    info = InfoOf(replica);
  }
  EXPECT_EQ(info.busy(), 0u);
  EXPECT_EQ(info.waiting(), 0u);
  EXPECT_EQ(tally.hung, 0);
  // Back to the baseline.
  ExpectBackToBaseline("bsls-processd", replica.pid(), fresh, baseline, warm_s, load_s);
  // Every upload's scratch folder is gone.
  EXPECT_TRUE(fs::is_empty(scratch)) << fs::begin(fs::directory_iterator(scratch))->path();
  // The service's own failures (a status that says it broke, not the caller).
  EXPECT_TRUE(tally.suspicious.empty()) << "see SUSPICIOUS above";
  // A clean drain; under the sanitizers also no leak.
  EXPECT_EQ(replica.Terminate(), 0) << replica.Log().substr(0, 20000);
  std::error_code ec;
  if (!HasFailure()) fs::remove_all(folder, ec);
}

// ---------------------------------------------------------------------------
// bslsd

// Sets the string field `name` of `message` if it has one.
void SetStringField(pb::Message* message, const std::string& name, const std::string& value) {
  if (const pb::FieldDescriptor* f = message->GetDescriptor()->FindFieldByName(name);
      f && f->cpp_type() == pb::FieldDescriptor::CPPTYPE_STRING && !f->is_repeated())
    message->GetReflection()->SetString(message, f, value);
}

// bslsd's methods with valid examples and hand-picked damage; `capture_id`
// names a stored capture.
Corpus BslsdCorpus(const std::string& capture_id) {
  Corpus c;
  c.service = "bsls.v1.CaptureDaemon";
  c.methods =
      MethodsOf(pb::DescriptorPool::generated_pool()->FindServiceByName("bsls.v1.CaptureDaemon"));
  c.default_deadline_ms = 10000;
  for (const char* work : {"Grab", "SetSlide", "SetFocus", "SelectCamera"})
    c.deadline_ms[work] = 30000;
  // Streams without an end of their own: a valid one runs until its deadline.
  for (const char* stream : {"StreamPreview", "WatchEvents"}) c.deadline_ms[stream] = 500;
  c.oversized_bytes = 70 << 10;  // above max_receive_message_bytes (64 KiB)
  // Valid examples: quick ones (a grab of one side, the slide already in place).
  for (const Method& m : c.methods) {
    std::unique_ptr<pb::Message> message = Parse(m.input, "");
    // A real capture to read; one of a valid form that does not exist to delete.
    SetStringField(message.get(), "capture_id",
                   m.name == "DeleteCapture" ? "0123456789abcdef0123456789abcdef" : capture_id);
    c.examples[m.name] = {Serialized(*message)};
  }
  v1::SelectCameraRequest select;
  select.set_camera(v1::CAMERA_LEFT);
  c.examples["SelectCamera"] = {Serialized(select)};
  v1::PreviewRequest preview;
  preview.set_camera(v1::CAMERA_LEFT);
  c.examples["StreamPreview"] = {Serialized(preview)};
  v1::GrabRequest grab;
  grab.set_side(v1::GRAB_SIDE_LEFT);
  grab.set_session_id("robust");
  grab.set_patient_reference("P-0001");
  c.examples["Grab"] = {Serialized(grab)};
  v1::ListCapturesRequest list;
  list.set_page_size(10);
  c.examples["ListCaptures"] = {Serialized(list)};
  v1::SetSlideRequest slide;
  slide.set_slide(1);
  c.examples["SetSlide"] = {Serialized(slide)};
  v1::SetFocusRequest focus;
  focus.set_steps(1);
  c.examples["SetFocus"] = {Serialized(focus)};
  v1::SetLampRequest lamp;
  lamp.set_on(true);
  c.examples["SetLamp"] = {Serialized(lamp)};

  auto call_of = [](const pb::Message& request, const std::string& category) {
    RawCall call;
    call.messages = {Serialized(request)};
    call.category = category;
    return call;
  };
  const auto ints = std::vector<int>{
      0, -1, 4, 99, std::numeric_limits<int>::min(), std::numeric_limits<int>::max(), 1001, -1001};
  c.targeted["SelectCamera"].push_back([=](Rng& rng) {
    v1::SelectCameraRequest r;
    r.set_camera(static_cast<v1::Camera>(OneOf<int>(rng, {0, 3, 4, 99, -1})));
    return call_of(r, "camera");
  });
  c.targeted["SetGain"].push_back([=](Rng& rng) {
    v1::SetGainRequest r;
    r.set_gain(OneOf(rng, ints));
    return call_of(r, "gain");
  });
  c.targeted["StreamPreview"].push_back([=](Rng& rng) {
    v1::PreviewRequest r;
    r.set_camera(static_cast<v1::Camera>(OneOf<int>(rng, {99, -1, 3, 4})));
    r.set_decimation(OneOf<std::uint32_t>(rng, {251, std::numeric_limits<std::uint32_t>::max()}));
    return call_of(r, "camera, decimation");
  });
  c.targeted["StreamPreview"].push_back([=](Rng& rng) {  // a real stream, abandoned
    RawCall call = call_of(preview, "cancelled stream");
    if (Pick(rng, 2))
      call.cancel_after_replies = 1;
    else
      call.cancel_after_ms = Pick(rng, 150);
    if (Pick(rng, 3) == 0) call.half_close = false;
    return call;
  });
  c.targeted["Grab"].push_back([=](Rng& rng) {
    v1::GrabRequest r = grab;
    switch (Pick(rng, 4)) {
      case 0:
        r.set_side(static_cast<v1::GrabSide>(OneOf<int>(rng, {0, 4, 99, -1})));
        break;
      case 1:
        r.set_session_id(
            OneOf<std::string>(rng, {std::string(257, 's'), std::string(60 << 10, 's')}));
        break;
      case 2:
        r.set_patient_reference(std::string(257 + Pick(rng, 60000), 'p'));
        break;
      default:
        r.set_session_id(std::string(70 << 10, 's'));  // above the receive limit
    }
    return call_of(r, "side, texts");
  });
  c.targeted["Grab"].push_back([=](Rng& rng) {  // a real grab, abandoned (rarely)
    v1::GrabRequest r = grab;
    if (Pick(rng, 8) != 0) r.set_side(v1::GRAB_SIDE_UNSPECIFIED);
    RawCall call = call_of(r, "cancelled grab");
    call.cancel_after_ms = 1 + Pick(rng, 40);
    return call;
  });
  c.targeted["ListCaptures"].push_back([=](Rng& rng) {
    v1::ListCapturesRequest r;
    switch (Pick(rng, 5)) {
      case 0:
        r.set_page_size(OneOf(rng, ints));
        break;
      case 1:
        r.set_page_token(OneOf<std::string>(
            rng, {"garbage", std::string(60 << 10, 't'), std::string(1, '\0'), "-1",
                  "99999999999999999999999", "/../../etc/passwd", "\xff\xfe"}));
        break;
      case 2:
      case 3: {
        google::protobuf::Timestamp* t =
            Pick(rng, 2) ? r.mutable_taken_from() : r.mutable_taken_before();
        t->set_seconds(OneOf<std::int64_t>(
            rng, {std::numeric_limits<std::int64_t>::max(),
                  std::numeric_limits<std::int64_t>::min(), -1, 253402300800, -62135596801}));
        t->set_nanos(OneOf<int>(rng, {0, -1, 2000000000, std::numeric_limits<int>::min()}));
        break;
      }
      default:
        r.set_session_id(std::string(60 << 10, 's'));
        r.set_patient_reference(AbsurdText(rng));
    }
    return call_of(r, "page, times, filters");
  });
  const std::vector<std::string> ids = {"",
                                        "../../../../etc/passwd",
                                        "/etc/passwd",
                                        std::string(32, 'g'),
                                        std::string(32, 'a'),
                                        std::string(32, 'A'),
                                        std::string(31, 'a'),
                                        std::string(33, 'a'),
                                        std::string(32, '\0'),
                                        std::string(60 << 10, 'a'),
                                        "0123456789abcdef0123456789abcde/",
                                        "\xff\xfe"};
  for (const Method& m : c.methods) {
    if (!m.input->FindFieldByName("capture_id")) continue;
    const pb::Descriptor* input = m.input;
    c.targeted[m.name].push_back([=](Rng& rng) {
      std::unique_ptr<pb::Message> r = Parse(input, "");
      SetStringField(r.get(), "capture_id", OneOf(rng, ids));
      RawCall call;
      call.messages = {Serialized(*r)};
      call.category = "capture id";
      return call;
    });
    if (input->FindFieldByName("name"))  // GetCaptureResult: a file of a real capture
      c.targeted[m.name].push_back([=](Rng& rng) {
        std::unique_ptr<pb::Message> r = Parse(input, "");
        SetStringField(r.get(), "capture_id", capture_id);
        SetStringField(r.get(), "name",
                       OneOf<std::string>(
                           rng, {"../../../../etc/passwd", "/etc/passwd", "..", "record.json/..",
                                 std::string(60 << 10, 'n'), std::string(1, '\0'), "surface.ply"}));
        RawCall call;
        call.messages = {Serialized(*r)};
        call.category = "result name";
        return call;
      });
  }
  c.targeted["SetSlide"].push_back([=](Rng& rng) {
    v1::SetSlideRequest r;
    r.set_slide(OneOf<int>(
        rng, {0, 4, -1, std::numeric_limits<int>::min(), std::numeric_limits<int>::max()}));
    return call_of(r, "slide");
  });
  c.targeted["SetFocus"].push_back([=](Rng& rng) {
    v1::SetFocusRequest r;
    r.set_steps(OneOf<int>(
        rng, {1001, -1001, std::numeric_limits<int>::min(), std::numeric_limits<int>::max()}));
    return call_of(r, "steps");
  });
  c.targeted["WatchEvents"].push_back([=](Rng& rng) {
    RawCall call = call_of(v1::WatchEventsRequest(), "abandoned stream");
    call.cancel_after_ms = Pick(rng, 200);
    if (Pick(rng, 2)) call.half_close = false;
    return call;
  });
  return c;
}

// bslsd takes 10,000 malformed requests and comes back to its baseline,
// alive and answering.
TEST(MalformedRequests, BslsdSurvivesTenThousand) {
  google::protobuf::SetLogHandler(&QuietProtobuf);
  const fs::path dir = testing::MakeDaemonDir("malformed");
  const fs::path config = testing::WriteDaemonConfig(dir, "roles:\n  admin: [root]\n");
  testing::DaemonProcess daemon(dir, config);
  ASSERT_TRUE(daemon.ready()) << daemon.Log();
  auto stub = daemon.Stub();
  auto grab_one = [&](std::string* id) {
    v1::GrabRequest request;
    request.set_side(v1::GRAB_SIDE_LEFT);
    request.set_session_id("robust");
    v1::GrabResponse reply;
    const grpc::Status status =
        stub->Grab(testing::Deadline(std::chrono::milliseconds(60000)).get(), request, &reply);
    if (id) *id = reply.capture().capture_id();
    return status;
  };
  auto answers = [&] {
    v1::DeviceStatus status;
    const grpc::Status s =
        stub->GetStatus(testing::Deadline(std::chrono::milliseconds(20000)).get(), {}, &status);
    if (!s.ok()) return ::testing::AssertionFailure() << "GetStatus: " << s.error_message();
    v1::ListCapturesResponse list;
    const grpc::Status l =
        stub->ListCaptures(testing::Deadline(std::chrono::milliseconds(20000)).get(), {}, &list);
    if (!l.ok() || list.captures().empty())
      return ::testing::AssertionFailure() << "ListCaptures: " << l.error_message();
    const grpc::Status g = grab_one(nullptr);
    if (!g.ok()) return ::testing::AssertionFailure() << "Grab: " << g.error_message();
    return ::testing::AssertionSuccess();
  };
  std::string capture_id;
  ASSERT_TRUE(grab_one(&capture_id).ok()) << daemon.Log();
  const Corpus corpus = BslsdCorpus(capture_id);
  const std::string target = "unix:" + daemon.socket().string();
  const auto open = [&](int n) { return FreshChannel(target, n); };

  const Footprint fresh = FootprintOf(daemon.pid());
  const auto warm_start = Clock::now();
  RunLoad(corpus, kWarmUpRequests, 1, open);
  ASSERT_FALSE(daemon.exited()) << "bslsd died in the warm-up\n" << daemon.Log();
  ASSERT_TRUE(answers()) << daemon.Log();
  std::this_thread::sleep_for(std::chrono::seconds(2));
  const Footprint baseline = FootprintOf(daemon.pid());
  const double warm_s = std::chrono::duration<double>(Clock::now() - warm_start).count();

  const auto load_start = Clock::now();
  const Tally tally = RunLoad(corpus, kRequests, 2, open);
  const double load_s = std::chrono::duration<double>(Clock::now() - load_start).count();
  Print("bslsd", tally);

  ASSERT_FALSE(daemon.exited()) << "bslsd died\n" << daemon.Log();
  EXPECT_TRUE(answers()) << daemon.Log();
  EXPECT_EQ(tally.hung, 0);
  stub.reset();
  ExpectBackToBaseline("bslsd", daemon.pid(), fresh, baseline, warm_s, load_s);
  EXPECT_TRUE(tally.suspicious.empty()) << "see SUSPICIOUS above";
  EXPECT_EQ(daemon.Terminate(), 0) << daemon.Log().substr(0, 20000);
  std::error_code ec;
  if (!HasFailure()) fs::remove_all(dir, ec);
}

}  // namespace
}  // namespace bsls::processing::test
