// The host of the test executables' precompiled header (tests/support/CMakeLists.txt): no tests.
