# EICAL_SANITIZE=address,undefined or thread applies to every target of this build tree.
if(EICAL_SANITIZE)
  add_compile_options(-fsanitize=${EICAL_SANITIZE} -fno-omit-frame-pointer -fno-sanitize-recover=all)
  add_link_options(-fsanitize=${EICAL_SANITIZE})
endif()
# EICAL_SANITIZED: a sanitizer runs in this tree (EICAL_SANITIZE, or EICAL_FUZZ's ASan and
# UBSan). The tests read it (the sanitizers replace operator new, so allocations are
# counted in the plain build only), and the suites that take minutes under a sanitizer are
# left out (tests/CMakeLists.txt). GCC says so with __SANITIZE_ADDRESS__, clang 14 does not.
if(EICAL_SANITIZE OR EICAL_FUZZ)
  set(EICAL_SANITIZED ON)
  add_compile_definitions(EICAL_SANITIZED=1)
else()
  set(EICAL_SANITIZED OFF)
endif()
