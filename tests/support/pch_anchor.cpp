// The translation unit that carries the test suites' shared precompiled header
// (tests/CMakeLists.txt, eical_test_pch): the header is built once and every suite reuses it.
