#pragma once
// The executor dsp/ takes for independent work (dsp/core/parallel_for.hpp), on threads:
// the tasks are shared out among up to `threads` threads (0: one per core), the calling
// thread among them. For evaluations (the uncertainty's draws), never for the per-sample
// path: each call starts its threads and joins them. Header-only, so that the
// ThreadSanitizer stage checks it without compiling the drivers (tests/threads).
#include "dsp/core/parallel_for.hpp"

#include <algorithm>
#include <atomic>
#include <exception>
#include <mutex>
#include <system_error>
#include <thread>
#include <vector>

namespace eical::drivers {

inline dsp::ParallelFor thread_for(unsigned threads = 0) {
  const unsigned n_threads = threads > 0 ? threads : std::max(1U, std::thread::hardware_concurrency());
  return [n_threads](std::size_t count, const dsp::ParallelTask& task) {
    std::atomic<std::size_t> next{0};
    std::exception_ptr first_error;
    std::mutex error_mutex;
    auto work = [&] {
      for (std::size_t i = next++; i < count; i = next++) {
        try {
          task(i);
        } catch (...) {
          const std::lock_guard<std::mutex> lock(error_mutex);
          if (!first_error) first_error = std::current_exception();
        }
      }
    };
    std::vector<std::thread> helpers;
    const std::size_t extra = count > 0 ? std::min<std::size_t>(n_threads, count) - 1 : 0;
    try {
      helpers.reserve(extra);
      for (std::size_t t = 0; t < extra; ++t) helpers.emplace_back(work);
    } catch (const std::system_error&) {  // no thread to be had: fewer helpers, the same result
    }
    work();
    for (std::thread& h : helpers) h.join();
    if (first_error) std::rethrow_exception(first_error);
  };
}

}  // namespace eical::drivers
