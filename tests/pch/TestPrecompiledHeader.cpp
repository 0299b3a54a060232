// Builds the precompiled header that every test suite reuses (tests/CMakeLists.txt): the header itself is
// forced into this file, which needs nothing else.
