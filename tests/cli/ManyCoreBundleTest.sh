#!/usr/bin/env bash
# The 16-core machine's bundle (tools/manycore/bundle.sh) runs as it will there: copied into an empty folder,
# with an empty environment (no LD_LIBRARY_PATH, no PATH), through its launcher only; every library the
# loader resolves is the bundle's own; one short benchmark prints its figures.
# Usage: ManyCoreBundleTest.sh <repository> <Release build folder> <scratch folder>; exit 77 (skip) without
# ../shared/bench.
set -u
repository="$1"
build="$2"
work="$3"
fail() {
    echo "FAIL: $*"
    exit 1
}
shared="${CAIRN_SHARED_DIR:-$repository/../shared}/bench"
[ -f "$shared/SPEC.md" ] || { echo "SKIP: no $shared"; exit 77; }
rm -rf "$work" && mkdir -p "$work/empty" || exit 2
# A program from outside the build rides along as the Jolt harness will (CAIRN_BUNDLE_EXTRA): any dynamically
# linked one does
extra=$(type -P true) || fail "no true(1) to bundle as an outside program"
CAIRN_BUNDLE_NO_BUILD=1 CAIRN_BUNDLE_BUILD="$build" CAIRN_BUNDLE_EXTRA="$extra" \
    bash "$repository/tools/manycore/bundle.sh" "$work/bundle" >"$work/bundle.log" 2>&1 ||
    fail "bundle.sh failed: $(cat "$work/bundle.log")"
cp -r "$work/bundle" "$work/empty/bundle"
copy="$work/empty/bundle"
cd "$work/empty" || exit 2

for program in "$copy"/bin/*; do
    resolved=$(env -i "$copy/lib/ld-linux-x86-64.so.2" --inhibit-cache --library-path "$copy/lib" --list "$program" 2>&1) ||
        fail "the bundled loader cannot resolve $(basename "$program"): $resolved"
    outside=$(echo "$resolved" | awk '$2 == "=>" && $3 !~ /^\// && $3 != "" { print } $2 == "=>" && $3 ~ /^\// { print $3 }' |
        grep -v "^$copy/lib/" || true)
    [ -z "$outside" ] || fail "$(basename "$program") loads libraries from outside the bundle: $outside"
done

output=$(env -i "$copy/run" cairn-bench-unionfind --benchmark_min_time=0.01 --benchmark_filter='uf_union/0/1' 2>&1) ||
    fail "the bundled union-find benchmark failed: $output"
echo "$output" | grep -q "ns_per_union=" || fail "no figures from the bundled benchmark: $output"
[ -x "$copy/bin/true" ] || fail "the outside program (CAIRN_BUNDLE_EXTRA=$extra) is not in the bundle"
output=$(env -i "$copy/run" true 2>&1) || fail "the bundled outside program failed: $output"
echo "many-core bundle: $(tail -1 "$work/bundle.log")"
echo "many-core bundle: all checks passed"
