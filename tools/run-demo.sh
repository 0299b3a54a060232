#!/usr/bin/env bash
# Installs what is missing, builds and runs the streaming open-world demo (about a minute on 2 cores).
# Usage: bash tools/run-demo.sh [demo flags, see --help]; the report goes to ./demo-output unless --output says.
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
bash "$root/tools/setup.sh"
cmake -S "$root" -B "$root/build/release" -G Ninja -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build "$root/build/release" -j "$(nproc)" --target cairn-demo
exec "$root/build/release/tools/cairn-demo" "$@"
