#!/usr/bin/env bash
# Builds and runs every test: the Release suites, the concurrency suite under ThreadSanitizer, every suite
# under AddressSanitizer+UndefinedBehaviorSanitizer (Clang, with the libFuzzer harnesses replaying their
# corpus), then each fuzz harness for 30 s.
# Usage: bash tools/run-tests.sh   (installs missing Debian packages first)
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
bash "$root/tools/setup.sh"
jobs=$(nproc)
# Unity builds: each target's sources compile in batches of 16, so the headers (Eigen's, GoogleTest's) and the
# templates they instantiate are compiled once a batch rather than once a source. That halves the builds'
# time, most of this script's. Their trees are this script's own (build/ci/): batching changes what the
# compiler inlines (step_ragdolls ran about 2 % slower), so build/release, which the demo script, the
# benchmarks and the 16-core bundle use, stays a build of one source at a time, as do the presets' trees
unity=(-DCMAKE_UNITY_BUILD=ON -DCMAKE_UNITY_BUILD_BATCH_SIZE=16)
ci="$root/build/ci"
# Each part's wall time, so that a run's log says where its minutes went
mark=$SECONDS
took() {
    echo "-- $1 took $((SECONDS - mark)) s"
    mark=$SECONDS
}

echo "== Release build and tests"
cmake -S "$root" -B "$ci/release" -G Ninja -DCMAKE_BUILD_TYPE=Release "${unity[@]}"
cmake --build "$ci/release" -j "$jobs"
took "Release build"
ctest --test-dir "$ci/release" --output-on-failure -j "$jobs" -LE long
took "Release tests"

echo "== ThreadSanitizer build and concurrency tests"
# Line tables (-g1) are all ThreadSanitizer's reports need for their stacks; full debug info cost a quarter
# of each source's compile
cmake -S "$root" -B "$ci/tsan" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo \
    "-DCMAKE_CXX_FLAGS_RELWITHDEBINFO=-O2 -g1 -DNDEBUG" -DCAIRN_SANITIZER=thread -DCAIRN_BUILD_TOOLS=OFF "${unity[@]}"
cmake --build "$ci/tsan" -j "$jobs" --target cairn_concurrency_tests
took "ThreadSanitizer build"
TSAN_OPTIONS="halt_on_error=1 second_deadlock_stack=1" \
    ctest --test-dir "$ci/tsan" --output-on-failure -j "$jobs" -L concurrency -LE long
took "ThreadSanitizer tests"

echo "== ASan+UBSan build (Clang, with the fuzz harnesses) and every test but the long ones"
cmake -S "$root" -B "$ci/asan" -G Ninja -DCMAKE_CXX_COMPILER=clang++ -DCMAKE_BUILD_TYPE=RelWithDebInfo \
    "-DCMAKE_CXX_FLAGS_RELWITHDEBINFO=-O1 -gline-tables-only" -DCAIRN_SANITIZER=address \
    -DCAIRN_BUILD_BENCHMARKS=OFF -DCAIRN_BUILD_FUZZERS=ON "${unity[@]}"
cmake --build "$ci/asan" -j "$jobs"
took "ASan+UBSan build"
# A sanitizer finding ends its test at once (UBSan's are made fatal at compile time too)
ASAN_OPTIONS="halt_on_error=1:detect_leaks=1" UBSAN_OPTIONS="halt_on_error=1:print_stacktrace=1" \
    ctest --test-dir "$ci/asan" --output-on-failure -j "$jobs" -LE long
took "ASan+UBSan tests"

echo "== Fuzzing: each harness 30 s from its seed corpus"
CAIRN_FUZZ_BUILD="$ci/asan" bash "$root/tools/fuzz.sh" 30
took "Fuzzing"
echo "-- the whole test command took $SECONDS s"
