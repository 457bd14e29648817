# EICAL_FUZZ=ON (clang only): every target of this build tree is compiled with libFuzzer's
# coverage instrumentation and ASan + UBSan, and fuzz/ adds one libFuzzer executable per
# reader (scripts/fuzz-short runs them; fuzz/README.md).
option(EICAL_FUZZ "Build the libFuzzer targets in fuzz/ (needs clang)" OFF)
if(EICAL_FUZZ)
  if(NOT CMAKE_CXX_COMPILER_ID STREQUAL "Clang")
    message(FATAL_ERROR "EICAL_FUZZ needs clang (configure with CC=clang CXX=clang++), not ${CMAKE_CXX_COMPILER_ID}")
  endif()
  if(EICAL_SANITIZE)
    message(FATAL_ERROR "EICAL_FUZZ brings its own sanitizers (address,undefined): leave EICAL_SANITIZE empty")
  endif()
  # fuzzer-no-link: coverage for libFuzzer in the libraries; only fuzz/*'s executables link
  # libFuzzer's main (-fsanitize=fuzzer).
  add_compile_options(-fsanitize=fuzzer-no-link,address,undefined -fno-omit-frame-pointer -fno-sanitize-recover=all)
  add_link_options(-fsanitize=address,undefined)
endif()
