#!/usr/bin/env bash
# Builds and runs every test: the Release suites, then the concurrency suite under ThreadSanitizer.
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
