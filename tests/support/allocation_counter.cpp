#include "tests/support/allocation_counter.hpp"

#include <cstdlib>
#include <new>

namespace {
thread_local bool t_counting = false;
thread_local std::size_t t_allocations = 0;
}  // namespace

#if defined(EICAL_SANITIZED)
namespace eical::test {
bool allocations_counted() { return false; }
}  // namespace eical::test
#else
namespace eical::test {
bool allocations_counted() { return true; }
}  // namespace eical::test
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmismatched-new-delete"
void* operator new(std::size_t n) {
  if (t_counting) ++t_allocations;
  if (void* p = std::malloc(n ? n : 1)) return p;
  throw std::bad_alloc();
}
void operator delete(void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }
#pragma GCC diagnostic pop
#endif

namespace eical::test {

void start_counting_allocations() {
  t_allocations = 0;
  t_counting = true;
}

std::size_t stop_counting_allocations() {
  t_counting = false;
  return t_allocations;
}

}  // namespace eical::test
