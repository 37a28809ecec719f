// Latency of CaptureStore::Put for a two-frame capture (left + right) at
// several frame sizes, 512x512 being the thesis framestore's: every put is
// durable (4 fsyncs: two frame files, the frames directory, the WAL), so the
// figure is dominated by the disk under TMPDIR. Reported per size: median and
// 99th percentile of single puts (counters p50_ms, p99_ms), plus Get
// (read + SHA-256 verification) for comparison.
#include <benchmark/benchmark.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <random>
#include <string>
#include <vector>

#include "bsls/store/capture_store.h"

namespace bsls::store {
namespace {

std::string TempRoot() {
  const char* base = std::getenv("TMPDIR");
  std::string pattern = std::string(base ? base : "/tmp") + "/bsls-store-bench-XXXXXX";
  return ::mkdtemp(pattern.data()) ? pattern : std::string();
}

CaptureRequest Request(int side) {
  std::mt19937 rng(7);
  CaptureRequest request;
  request.session_id = "bench";
  request.patient_reference = "p";
  request.side = Side::kBoth;
  request.slide = 2;
  request.software_version = "bench";
  for (auto camera : {framestore::Camera::kLeft, framestore::Camera::kRight}) {
    framestore::GreyFrame frame;
    frame.width = frame.height = frame.stride = side;
    frame.pixels.resize(static_cast<std::size_t>(side) * side);
    for (auto& pixel : frame.pixels) pixel = static_cast<std::uint8_t>(rng());
    frame.camera = camera;
    frame.timestamps.wall = std::chrono::system_clock::now();
    request.frames.push_back(std::move(frame));
  }
  return request;
}

double Percentile(std::vector<double> values, double fraction) {
  if (values.empty()) return 0;
  std::sort(values.begin(), values.end());
  const auto index = static_cast<std::size_t>(fraction * static_cast<double>(values.size() - 1));
  return values[index];
}

// A store in `root` without a free-space reserve; on failure the benchmark
// is marked skipped with the reason.
Result<std::unique_ptr<CaptureStore>> OpenStore(const std::string& root, benchmark::State& state) {
  CaptureStoreOptions options;
  options.root = root;
  options.free_space_reserve_bytes = 0;
  auto store = CaptureStore::Open(options);
  if (!store.ok()) state.SkipWithError(store.status().ToString().c_str());
  return store;
}

void BM_PutTwoFrames(benchmark::State& state) {
  const std::string root = TempRoot();
  auto store = OpenStore(root, state);
  if (!store.ok()) return;
  const CaptureRequest request = Request(static_cast<int>(state.range(0)));
  std::vector<double> millis;
  for (auto _ : state) {
    const auto start = std::chrono::steady_clock::now();
    auto put = (*store)->Put(request);
    millis.push_back(
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
            .count());
    if (!put.ok()) {
      state.SkipWithError(put.status().ToString().c_str());
      break;
    }
  }
  state.counters["p50_ms"] = Percentile(millis, 0.5);
  state.counters["p99_ms"] = Percentile(millis, 0.99);
  state.SetBytesProcessed(static_cast<std::int64_t>(state.iterations()) * 2 * state.range(0) *
                          state.range(0));
  store->reset();
  std::filesystem::remove_all(root);
}
BENCHMARK(BM_PutTwoFrames)
    ->Arg(256)
    ->Arg(512)
    ->Arg(1024)
    ->Unit(benchmark::kMillisecond)
    ->Iterations(200);

void BM_GetTwoFrames(benchmark::State& state) {
  const std::string root = TempRoot();
  auto store = OpenStore(root, state);
  if (!store.ok()) return;
  auto put = (*store)->Put(Request(static_cast<int>(state.range(0))));
  if (!put.ok()) {
    state.SkipWithError(put.status().ToString().c_str());
    return;
  }
  for (auto _ : state) {
    auto got = (*store)->Get(put->id.str());
    if (!got.ok()) {
      state.SkipWithError(got.status().ToString().c_str());
      break;
    }
    benchmark::DoNotOptimize(got->frames.data());
  }
  store->reset();
  std::filesystem::remove_all(root);
}
BENCHMARK(BM_GetTwoFrames)->Arg(512)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace bsls::store

BENCHMARK_MAIN();
