#pragma once
// Counts the allocations of the calling thread between start() and stop() (operator new
// is replaced in allocation_counter.cpp; sanitizer builds keep theirs and count nothing).
#include <cstddef>

namespace eical::test {

bool allocations_counted();  // false in sanitizer builds
void start_counting_allocations();
std::size_t stop_counting_allocations();  // allocations of this thread since start

}  // namespace eical::test
