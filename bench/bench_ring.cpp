// Two-thread throughput of eical's SPSC ring against boost::lockfree::spsc_queue with the
// same capacity and payloads (the 128-byte Frame and an 8-byte word). Prints the ratio.
#include "drivers/ring/spsc_ring.hpp"
#include "dsp/core/frame.hpp"

#include <benchmark/benchmark.h>
#include <boost/lockfree/spsc_queue.hpp>

#include <cstdio>
#include <map>
#include <string>
#include <thread>

namespace {

constexpr std::size_t kCapacity = 4096;
constexpr std::int64_t kItems = 2'000'000;

template <class T>
T make(std::int64_t i) {
  if constexpr (std::is_same_v<T, eical::dsp::Frame>) {
    eical::dsp::Frame f;
    f.sample_index = i;
    return f;
  } else {
    return static_cast<T>(i);
  }
}

template <class T>
std::int64_t key(const T& v) {
  if constexpr (std::is_same_v<T, eical::dsp::Frame>)
    return v.sample_index;
  else
    return static_cast<std::int64_t>(v);
}

template <class T>
void BM_eical(benchmark::State& state) {
  for (auto _ : state) {
    eical::drivers::SpscRing<T> ring(kCapacity);
    std::thread producer([&] {
      for (std::int64_t i = 0; i < kItems; ++i)
        while (!ring.try_push(make<T>(i))) {
        }
    });
    T v{};
    std::int64_t got = 0, sum = 0;
    while (got < kItems)
      if (ring.try_pop(v)) ++got, sum += key(v);
    producer.join();
    benchmark::DoNotOptimize(sum);
  }
  state.SetItemsProcessed(state.iterations() * kItems);
}

template <class T>
void BM_boost(benchmark::State& state) {
  for (auto _ : state) {
    boost::lockfree::spsc_queue<T, boost::lockfree::capacity<kCapacity>> q;
    std::thread producer([&] {
      for (std::int64_t i = 0; i < kItems; ++i)
        while (!q.push(make<T>(i))) {
        }
    });
    T v{};
    std::int64_t got = 0, sum = 0;
    while (got < kItems)
      if (q.pop(v)) ++got, sum += key(v);
    producer.join();
    benchmark::DoNotOptimize(sum);
  }
  state.SetItemsProcessed(state.iterations() * kItems);
}

BENCHMARK(BM_eical<eical::dsp::Frame>)->Name("ring/eical/Frame")->UseRealTime()->Unit(benchmark::kMillisecond);
BENCHMARK(BM_boost<eical::dsp::Frame>)->Name("ring/boost/Frame")->UseRealTime()->Unit(benchmark::kMillisecond);
BENCHMARK(BM_eical<std::uint64_t>)->Name("ring/eical/u64")->UseRealTime()->Unit(benchmark::kMillisecond);
BENCHMARK(BM_boost<std::uint64_t>)->Name("ring/boost/u64")->UseRealTime()->Unit(benchmark::kMillisecond);

// Collects items/s per benchmark so the ratio can be printed after the run.
class RatioReporter : public benchmark::ConsoleReporter {
 public:
  void ReportRuns(const std::vector<Run>& runs) override {
    for (const auto& r : runs) {
      const auto it = r.counters.find("items_per_second");
      if (it != r.counters.end()) rate_[r.benchmark_name()] = it->second.value;
    }
    ConsoleReporter::ReportRuns(runs);
  }
  void print_ratios() const {
    for (const char* payload : {"Frame", "u64"}) {
      const auto a = rate_.find(std::string("ring/eical/") + payload + "/real_time");
      const auto b = rate_.find(std::string("ring/boost/") + payload + "/real_time");
      if (a != rate_.end() && b != rate_.end() && b->second > 0)
        std::printf("ring throughput ratio (eical/boost, %s): %.2f  (%.1f vs %.1f M items/s)\n", payload,
                    a->second / b->second, a->second / 1e6, b->second / 1e6);
    }
  }

 private:
  std::map<std::string, double> rate_;
};

}  // namespace

int main(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  RatioReporter reporter;
  benchmark::RunSpecifiedBenchmarks(&reporter);
  reporter.print_ratios();
  benchmark::Shutdown();
  return 0;
}
