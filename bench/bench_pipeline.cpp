// Full streaming pipeline (Pipeline::step over every frame of a simulated R10 circle with
// sensor noise and the two PSD strips of configuration B: static compensation, Coriolis
// where asked, dynamic compensation, integration, standstill detector, PSD decoding and the
// live Kalman filter with ZUPT and CUPT) on one core: ns per 10 kHz frame for each arithmetic and dynamic variant,
// and the heap allocations after start-up (construction excluded), counted by a replaced
// operator new as tests/e2e/pipeline_allocation_test.cpp does.
#include "dsp/pipeline/pipeline.hpp"
#include "sim/simulate.hpp"

#include <benchmark/benchmark.h>

#include <atomic>
#include <cstdio>
#include <cstdlib>
#include <new>

namespace {
std::atomic<bool> g_counting{false};
std::atomic<std::size_t> g_allocations{0};
std::atomic<std::size_t> g_frames_counted{0};
}  // namespace

// The replacement pair is malloc/free by design; GCC cannot see that new and delete match.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmismatched-new-delete"
void* operator new(std::size_t n) {
  if (g_counting.load(std::memory_order_relaxed)) g_allocations.fetch_add(1, std::memory_order_relaxed);
  if (void* p = std::malloc(n ? n : 1)) return p;
  throw std::bad_alloc();
}
void operator delete(void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }
#pragma GCC diagnostic pop

namespace {

using namespace eical;

const dsp::Run& circle_run() {
  static const dsp::Run run = [] {
    sim::Scenario sc = sim::circle_scenario(10.0, 2500.0, 2);
    sc.meta.psd = sim::psd_config_b(10.0);
    return sim::simulate(sc);
  }();
  return run;
}

void run_pipeline(benchmark::State& state, dsp::PipelineConfig cfg) {
  const dsp::Run& run = circle_run();
  dsp::Pipeline p(cfg);  // start-up: reserves the trace
  for (auto _ : state) {
    state.PauseTiming();
    p.reset();
    state.ResumeTiming();
    g_counting = true;
    for (const auto& f : run.frames) p.step(f);
    g_counting = false;
    g_frames_counted += run.frames.size();
    benchmark::DoNotOptimize(p.live());
  }
  const double frames = static_cast<double>(run.frames.size()) * static_cast<double>(state.iterations());
  // CPU seconds per frame, printed with an SI prefix (e.g. 206n = 206 ns per frame).
  state.counters["per_frame"] = benchmark::Counter(frames, benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
  state.counters["frames"] = static_cast<double>(run.frames.size());
}

dsp::PipelineConfig base() { return dsp::pipeline_config(circle_run().meta, circle_run().frames.size()); }

void BM_PipelineDoubleTwoStage(benchmark::State& state) { run_pipeline(state, base()); }

void BM_PipelineDoubleTwoStageCoriolis(benchmark::State& state) {
  auto c = base();
  c.coriolis = true;
  run_pipeline(state, c);
}

void BM_PipelineDoubleAccelerationLevel(benchmark::State& state) {
  auto c = base();
  c.dynamic = dsp::DynamicComp::acceleration_level;
  run_pipeline(state, c);
}

void BM_PipelineFixedQTwoStage(benchmark::State& state) {
  auto c = base();
  c.arithmetic = dsp::Arithmetic::fixed_q;
  run_pipeline(state, c);
}

void BM_PipelineFixedQWithCrossTerms(benchmark::State& state) {  // the model inversion iterates
  auto c = base();
  c.arithmetic = dsp::Arithmetic::fixed_q;
  c.calibration[0].cross_g_per_g(0, 1) = 1e-3;
  run_pipeline(state, c);
}

BENCHMARK(BM_PipelineDoubleTwoStage)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_PipelineDoubleTwoStageCoriolis)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_PipelineDoubleAccelerationLevel)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_PipelineFixedQTwoStage)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_PipelineFixedQWithCrossTerms)->Unit(benchmark::kMillisecond);

}  // namespace

int main(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  (void)circle_run();  // simulate before anything is timed or counted
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  std::printf("heap allocations after start-up: %zu over %zu frames stepped\n", g_allocations.load(),
              g_frames_counted.load());
  return g_allocations.load() == 0 ? 0 : 1;
}
