// Render and ground-truth times of the simulator at the thesis image size
// (512 x 512) and a modern sensor size (2048 x 2048).
#include <benchmark/benchmark.h>

#include <filesystem>

#include "bsls/simulator/renderer.h"
#include "bsls/simulator/scene.h"

namespace bsls::simulator {
namespace {

Scene BenchScene(SurfaceKind kind, int size) {
  ThesisSceneOptions options;
  options.rig.width = size;
  options.rig.height = size;
  return ThesisScene(pattern::Side::kLeft, kind, options);
}

// Args: image size (px), supersampling n.
void BM_RenderFaceImage(benchmark::State& state) {
  const int size = static_cast<int>(state.range(0));
  RenderParams params;
  params.supersampling = static_cast<int>(state.range(1));
  const Renderer renderer(BenchScene(SurfaceKind::kFace, size), params);
  for (auto _ : state) benchmark::DoNotOptimize(renderer.RenderImage(1));
  state.SetItemsProcessed(state.iterations() * size * size);
}
BENCHMARK(BM_RenderFaceImage)
    ->Args({512, 2})
    ->Args({512, 3})
    ->Args({2048, 1})
    ->Args({2048, 2})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

void BM_RenderPlaneImage(benchmark::State& state) {
  const int size = static_cast<int>(state.range(0));
  RenderParams params;
  params.supersampling = static_cast<int>(state.range(1));
  const Renderer renderer(BenchScene(SurfaceKind::kPlane, size), params);
  for (auto _ : state) benchmark::DoNotOptimize(renderer.RenderImage(1));
  state.SetItemsProcessed(state.iterations() * size * size);
}
BENCHMARK(BM_RenderPlaneImage)
    ->Args({512, 3})
    ->Args({2048, 2})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

// Full frame: image plus ground truth (pixel maps, junctions, lines).
void BM_RenderFaceFrame(benchmark::State& state) {
  const int size = static_cast<int>(state.range(0));
  const Renderer renderer(BenchScene(SurfaceKind::kFace, size), RenderParams{});
  for (auto _ : state) benchmark::DoNotOptimize(renderer.Render());
  state.SetItemsProcessed(state.iterations() * size * size);
}
BENCHMARK(BM_RenderFaceFrame)->Arg(512)->Arg(2048)->Unit(benchmark::kMillisecond)->UseRealTime();

// Slide rasterisation and blur (once per Renderer).
void BM_PrepareRenderer(benchmark::State& state) {
  const Scene scene = BenchScene(SurfaceKind::kPlane, 512);
  for (auto _ : state) benchmark::DoNotOptimize(Renderer(scene, RenderParams{}));
}
BENCHMARK(BM_PrepareRenderer)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace
}  // namespace bsls::simulator

BENCHMARK_MAIN();
