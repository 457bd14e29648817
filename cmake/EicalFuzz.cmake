# EICAL_FUZZ=ON (clang only): every target of this build tree is compiled with libFuzzer's
# coverage instrumentation and ASan + UBSan, and fuzz/ adds one libFuzzer executable per
# reader (scripts/fuzz-short runs them; fuzz/README.md). scripts/test's sanitizer stage
# runs the ASan + UBSan tests in the same tree: the tests link no libFuzzer, and the
# sanitizer runtime takes the coverage counters.
option(EICAL_FUZZ "Build the libFuzzer targets in fuzz/ (needs clang)" OFF)
# Comparison tracing (-fsanitize-coverage=trace-cmp, part of fuzzer-no-link) lets libFuzzer
# solve the readers' comparisons, and runs a callback at every comparison of every
# library: the service's tests took minutes each under it. scripts/test's short run turns
# it off (edge counters only); the half-hour campaigns keep it.
option(EICAL_FUZZ_TRACE_CMP "libFuzzer's comparison tracing in every library (EICAL_FUZZ)" ON)
if(EICAL_FUZZ)
  if(NOT CMAKE_CXX_COMPILER_ID STREQUAL "Clang")
    message(FATAL_ERROR "EICAL_FUZZ needs clang (configure with CC=clang CXX=clang++), not ${CMAKE_CXX_COMPILER_ID}")
  endif()
  if(EICAL_SANITIZE)
    message(FATAL_ERROR "EICAL_FUZZ brings its own sanitizers (address,undefined): leave EICAL_SANITIZE empty")
  endif()
  # fuzzer-no-link: coverage for libFuzzer in the libraries; only fuzz/*'s executables link
  # libFuzzer's main (-fsanitize=fuzzer).
  if(EICAL_FUZZ_TRACE_CMP)
    add_compile_options(-fsanitize=fuzzer-no-link)
  else()
    add_compile_options(-fsanitize-coverage=inline-8bit-counters,pc-table)
  endif()
  add_compile_options(-fsanitize=address,undefined -fno-omit-frame-pointer -fno-sanitize-recover=all)
  add_link_options(-fsanitize=address,undefined)
endif()
