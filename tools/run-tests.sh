#!/usr/bin/env bash
# Builds and runs every test: the Release suites, the concurrency suite under ThreadSanitizer, every suite
# under AddressSanitizer+UndefinedBehaviorSanitizer (Clang, with the libFuzzer harnesses replaying their
# corpus), then each fuzz harness for 30 s.
# Usage: bash tools/run-tests.sh   (installs missing Debian packages first)
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
bash "$root/tools/setup.sh"
jobs=$(nproc)

echo "== Release build and tests"
cmake -S "$root" -B "$root/build/release" -G Ninja -DCMAKE_BUILD_TYPE=Release
cmake --build "$root/build/release" -j "$jobs"
ctest --test-dir "$root/build/release" --output-on-failure -j "$jobs" -LE long

echo "== ThreadSanitizer build and concurrency tests"
cmake -S "$root" -B "$root/build/tsan" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCAIRN_SANITIZER=thread \
    -DCAIRN_BUILD_TOOLS=OFF
cmake --build "$root/build/tsan" -j "$jobs" --target cairn_concurrency_tests
TSAN_OPTIONS="halt_on_error=1 second_deadlock_stack=1" \
    ctest --test-dir "$root/build/tsan" --output-on-failure -j "$jobs" -L concurrency -LE long

echo "== ASan+UBSan build (Clang, with the fuzz harnesses) and every test but the long ones"
cmake -S "$root" -B "$root/build/asan" -G Ninja -DCMAKE_CXX_COMPILER=clang++ -DCMAKE_BUILD_TYPE=RelWithDebInfo \
    "-DCMAKE_CXX_FLAGS_RELWITHDEBINFO=-O1 -gline-tables-only" -DCAIRN_SANITIZER=address \
    -DCAIRN_BUILD_BENCHMARKS=OFF -DCAIRN_BUILD_FUZZERS=ON
cmake --build "$root/build/asan" -j "$jobs"
# A sanitizer finding ends its test at once (UBSan's are made fatal at compile time too)
ASAN_OPTIONS="halt_on_error=1:detect_leaks=1" UBSAN_OPTIONS="halt_on_error=1:print_stacktrace=1" \
    ctest --test-dir "$root/build/asan" --output-on-failure -j "$jobs" -LE long

echo "== Fuzzing: each harness 30 s from its seed corpus"
CAIRN_FUZZ_BUILD="$root/build/asan" bash "$root/tools/fuzz.sh" 30
