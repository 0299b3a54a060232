#!/usr/bin/env bash
# The portable bundle for the 16-core machine (issue 29): the Release programs its run needs, every shared
# library they load with the dynamic loader and libc among them, ../shared/bench, a launcher and the run
# script, in one folder that runs on a bare x86-64 Linux with no packages and any glibc.
# Usage: bash tools/manycore/bundle.sh [OUT]          (default OUT: build/manycore-bundle, ignored by git)
#   CAIRN_BUNDLE_BUILD=<folder>  the Release build to take the programs from (default build/release)
#   CAIRN_BUNDLE_NO_BUILD=1      do not build them first (the ctest case, which runs after the build)
#   CAIRN_BUNDLE_EXTRA="<path>..." programs built outside the repository to bundle too, with their libraries:
#                                issue 29's Jolt harness (jolt-bench-step, which run.sh runs when the bundle has it)
# Then, on the machine: bash OUT/run-all.sh RESULTS_FOLDER   (or OUT/run PROGRAM ARGS... for one program)
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)
out=${1:-$root/build/manycore-bundle}
build=${CAIRN_BUNDLE_BUILD:-$root/build/release}
programs=(cairn-bench-broadphase cairn-bench-stages cairn-bench-step cairn-bench-unionfind cairn-demo)
limit=$((64 * 1024 * 1024))

if [ "${CAIRN_BUNDLE_NO_BUILD:-0}" != 1 ]; then
    cmake -S "$root" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=Release >/dev/null
    cmake --build "$build" -j "$(nproc)" --target "${programs[@]}"
fi
shared="${CAIRN_SHARED_DIR:-$root/../shared}/bench"
[ -f "$shared/SPEC.md" ] || { echo "bundle.sh: $shared (the shared workload) is missing" >&2; exit 1; }

extras=()
for extra in ${CAIRN_BUNDLE_EXTRA:-}; do
    [ -x "$extra" ] || { echo "bundle.sh: $extra (CAIRN_BUNDLE_EXTRA) is not an executable" >&2; exit 1; }
    extras+=("$extra")
done

rm -rf "$out"
mkdir -p "$out/bin" "$out/lib" "$out/shared"
for binary in "${programs[@]/#/$build/tools/}" "${extras[@]}"; do
    [ -x "$binary" ] || { echo "bundle.sh: $binary is not built" >&2; exit 1; }
    cp "$binary" "$out/bin/"
    # Every library the loader resolves ("name => path"), and the loader itself (a path alone)
    ldd "$binary" | awk '$2 == "=>" && $3 ~ /^\// { print $3 } $1 ~ /^\// { print $1 }' |
        while read -r library; do
            cp -L "$library" "$out/lib/$(basename "$library")"
        done
done
loader=$(ldd "$out/bin/${programs[0]}" | awk '$1 ~ /^\// { print $1 }')
[ -n "$loader" ] && [ -f "$out/lib/$(basename "$loader")" ] || { echo "bundle.sh: no dynamic loader" >&2; exit 1; }
cp -r "$shared" "$out/shared/bench"
# The demo's world: its default path is the source tree's, which the device's copy does not have
mkdir -p "$out/data/demo" && cp "$root/data/demo/world.json" "$out/data/demo/"
cp "$root/tools/manycore/run.sh" "$out/run-all.sh"

# The launcher: the bundled loader runs the program with the bundled libraries only; the system's are never
# searched (no LD_LIBRARY_PATH, no ld.so.cache of the bundle's loader reaches them)
cat >"$out/run" <<LAUNCHER
#!/bin/sh
# Usage: run PROGRAM [ARGS...]   (programs: ${programs[*]})
here=\$(cd "\$(dirname "\$0")" && pwd)
program=\$1
shift
export CAIRN_SHARED_DIR="\$here/shared"
exec "\$here/lib/$(basename "$loader")" --inhibit-cache --library-path "\$here/lib" --argv0 "\$program" \\
    "\$here/bin/\$program" "\$@"
LAUNCHER
chmod +x "$out/run"

size=$(du -sb "$out" | cut -f1)
if [ "$size" -gt "$limit" ]; then
    echo "bundle.sh: $out is $size bytes, over the 64 MiB a run may carry" >&2
    exit 1
fi
echo "bundle: $out, $((size / 1024)) KiB: ${programs[*]} ${extras[*]##*/}; $(ls "$out/lib" | wc -l) libraries"
