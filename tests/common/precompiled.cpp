// The translation unit that carries the test executables' precompiled header (tests/CMakeLists.txt,
// nbsim_test_pch): it compiles nothing of its own.
