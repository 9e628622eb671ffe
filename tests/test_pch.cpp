// The translation unit that builds the test binaries' precompiled header
// (tests/CMakeLists.txt, DRIVETWIN_TEST_PCH): the headers come from
// target_precompile_headers; this file adds nothing to them.
