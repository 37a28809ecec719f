// One grab through the ISA driver over the register-level card emulator
// (bus-clocked: 1 us per port access, as on the ISA bus). Wall time is what
// the driver and emulator cost on this machine; the counter emulated_ms is
// what the grab would take on the card itself, to compare with the thesis's
// process time (3.12, Equation 3.4: 1.66 s for the download alone).
// Report medians: --benchmark_repetitions=5 (set below).
#include <benchmark/benchmark.h>

#include <memory>

#include "bsls/framestore/isa_card_emulator.h"
#include "bsls/framestore/isa_framestore.h"

namespace bsls::framestore {
namespace {

std::shared_ptr<const VideoFrame> Gradient() {
  auto picture = std::make_shared<VideoFrame>();
  picture->pixels.resize(static_cast<std::size_t>(picture->width) * picture->height);
  for (int y = 0; y < picture->height; ++y) {
    for (int x = 0; x < picture->width; ++x) {
      picture->pixels[y * picture->width + x] = static_cast<std::uint8_t>((x + 3 * y) & 0xFF);
    }
  }
  return picture;
}

// Arg: the card's pair delay in PLD clocks (124: the thesis's PLD; 60: a
// faster PLD program, the least that leaves the host ~6 us per pair).
void BM_IsaGrabOverEmulator(benchmark::State& state) {
  IsaCardEmulatorParams card_params;
  card_params.pair_delay_clocks = static_cast<int>(state.range(0));
  card_params.oe_extend_clocks = std::min(32, card_params.pair_delay_clocks / 2);
  auto picture = Gradient();
  auto card = std::make_unique<IsaCardEmulator>(card_params,
                                                [picture](int, std::int64_t) { return picture; });
  IsaCardEmulator* emulator = card.get();
  auto framestore = IsaFramestore::Open(std::move(card), IsaFramestoreParams{});
  if (!framestore.ok()) {
    state.SkipWithError(framestore.status().ToString().c_str());
    return;
  }
  double emulated_ns = 0;
  for (auto _ : state) {
    const auto before = emulator->now();
    Result<GreyFrame> frame = (*framestore)->Grab();
    emulated_ns += static_cast<double>((emulator->now() - before).count());
    if (!frame.ok()) {
      state.SkipWithError(frame.status().ToString().c_str());
      return;
    }
    benchmark::DoNotOptimize(frame->pixels.data());
  }
  state.counters["emulated_ms"] =
      benchmark::Counter(emulated_ns / 1e6 / static_cast<double>(state.iterations()));
  state.counters["accesses"] = benchmark::Counter(
      static_cast<double>(emulator->counters().reads + emulator->counters().writes) /
      static_cast<double>(state.iterations() + 1));  // + Open
  state.SetItemsProcessed(state.iterations() * isa::kFrameWidth * isa::kFrameHeight);
}
BENCHMARK(BM_IsaGrabOverEmulator)
    ->Arg(124)
    ->Arg(60)
    ->Unit(benchmark::kMillisecond)
    ->Repetitions(5)
    ->ReportAggregatesOnly(true);

// The host side of a grab after the download: interleave and black-level
// extension of 512 x 512 (thesis 3.11), via a grab's pixel loop cost share.
void BM_ExtendBlackLevel(benchmark::State& state) {
  std::vector<std::uint8_t> codes(isa::kFrameWidth * isa::kFrameHeight);
  for (std::size_t i = 0; i < codes.size(); ++i) codes[i] = static_cast<std::uint8_t>(i);
  std::vector<std::uint8_t> out(codes.size());
  for (auto _ : state) {
    for (std::size_t i = 0; i < codes.size(); ++i) out[i] = ExtendBlackLevel(codes[i]);
    benchmark::DoNotOptimize(out.data());
  }
  state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(codes.size()));
}
BENCHMARK(BM_ExtendBlackLevel)->Unit(benchmark::kMicrosecond);

}  // namespace
}  // namespace bsls::framestore

BENCHMARK_MAIN();
