#!/usr/bin/env bash
# Fuzzes each libFuzzer harness of tests/fuzz for a given time, from its seed corpus, and prints what each did.
# Usage: bash tools/fuzz.sh [SECONDS] [HARNESS...]     (default: 30 s each, every harness)
# Needs a build with the harnesses (CAIRN_BUILD_FUZZERS, as the asan preset makes in build/asan and
# tools/run-tests.sh in build/ci/asan; another build folder with CAIRN_FUZZ_BUILD=...). Inputs the fuzzer adds go to <build>/fuzz-work/<harness>, never
# to the repository's seeds; an input that fails is saved as <build>/fuzz-artifacts/<harness>/crash-...
# (or timeout-, oom-), to be added to the seeds with its fix. Harnesses run as many at once as there are cores.
# CAIRN_FUZZ_RUNS=N stops each harness after N executions instead (SECONDS then caps the time).
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
build=${CAIRN_FUZZ_BUILD:-$root/build/asan}
seconds=${1:-30}
shift || true
harnesses=("$@")
if [ ${#harnesses[@]} -eq 0 ]; then
    harnesses=(fuzz_obj_mesh fuzz_gltf_mesh fuzz_navmesh_file fuzz_bake_summary fuzz_bake_config)
fi
case "$seconds" in '' | *[!0-9]*)
    echo "fuzz.sh: SECONDS must be a whole number, not '$seconds'" >&2
    exit 2
    ;;
esac

run_one() {
    local harness=$1 binary="$build/tests/fuzz/$1"
    local work="$build/fuzz-work/$harness" artifacts="$build/fuzz-artifacts/$harness"
    if [ ! -x "$binary" ]; then
        echo "fuzz.sh: $binary is not built (configure with -DCAIRN_BUILD_FUZZERS=ON)" >"$build/fuzz-$harness.log"
        return 1
    fi
    mkdir -p "$work" "$artifacts"
    # -timeout: one input running 10 s is a hang; the memory limits make a runaway allocation a finding
    local runs=()
    if [ -n "${CAIRN_FUZZ_RUNS:-}" ]; then runs=(-runs="$CAIRN_FUZZ_RUNS"); fi
    "$binary" -max_total_time="$seconds" "${runs[@]}" -timeout=10 -rss_limit_mb=2048 -malloc_limit_mb=2048 \
        -print_final_stats=1 -artifact_prefix="$artifacts/" "$work" "$root/tests/fuzz/corpus/$harness" \
        >"$build/fuzz-$harness.log" 2>&1
}

mkdir -p "$build"
pids=()
failed=0
for harness in "${harnesses[@]}"; do
    run_one "$harness" &
    pids+=($!)
    if [ ${#pids[@]} -ge "$(nproc)" ]; then
        wait "${pids[0]}" || failed=1
        pids=("${pids[@]:1}")
    fi
done
for pid in "${pids[@]}"; do
    wait "$pid" || failed=1
done

for harness in "${harnesses[@]}"; do
    log="$build/fuzz-$harness.log"
    runs=$(grep -o 'stat::number_of_executed_units: *[0-9]*' "$log" | grep -o '[0-9]*$' || true)
    speed=$(grep -o 'stat::average_exec_per_sec: *[0-9]*' "$log" | grep -o '[0-9]*$' || true)
    if grep -q 'ERROR: libFuzzer\|ERROR: AddressSanitizer\|runtime error\|SUMMARY: \|not built' "$log"; then
        echo "$harness: FAILED, see $log"
        grep -m 5 'ERROR\|SUMMARY\|runtime error\|Test unit written\|not built' "$log" || true
        failed=1
    else
        took=$(grep -o 'Done [0-9]* runs in [0-9]* second' "$log" | grep -o 'in [0-9]*' | grep -o '[0-9]*' || true)
        echo "$harness: ${runs:-?} executions in ${took:-?} s (${speed:-?}/s), $(ls "$build/fuzz-work/$harness" | wc -l) inputs in its working corpus, no finding"
    fi
done
exit $failed
