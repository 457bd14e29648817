#pragma once
// How dsp/ runs independent pieces of work side by side without knowing threads
// (architecture.md: no threads in dsp/): the caller hands in an executor, as it hands in
// spills (spill.hpp). parallel(count, task) calls task(i) once for every i in [0, count),
// in any order and on any thread, and returns when every call has returned; the first
// exception a task throws is rethrown to the caller after the others have finished. A task
// writes only its own slot of the result, so what dsp computes does not depend on the
// executor. The default runs the tasks in order on the caller's thread.
#include <cstddef>
#include <functional>

namespace eical::dsp {

using ParallelTask = std::function<void(std::size_t)>;
using ParallelFor = std::function<void(std::size_t count, const ParallelTask& task)>;

inline ParallelFor sequential_for() {
  return [](std::size_t count, const ParallelTask& task) {
    for (std::size_t i = 0; i < count; ++i) task(i);
  };
}

}  // namespace eical::dsp
