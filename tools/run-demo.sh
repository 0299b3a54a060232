#!/usr/bin/env bash
# Builds and runs the demo. Usage: bash tools/run-demo.sh [demo flags, see --help]
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
bash "$root/tools/setup.sh"
cmake -S "$root" -B "$root/build/release" -G Ninja -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build "$root/build/release" -j "$(nproc)" --target cairn-demo
exec "$root/build/release/tools/cairn-demo" "$@"
