#!/usr/bin/env bash
# cairn-demo's flags as a user mistypes them: each is refused before the run starts (within seconds, not
# after a minute of demo), with exit code 1 and a message naming the flag.
# Usage: DemoCommandLineTest.sh <cairn-demo> <scratch folder>
set -u
demo="$(realpath "$1")"
work="$2"
rm -rf "$work" && mkdir -p "$work" && cd "$work" || exit 2
fail() {
    echo "FAIL: $*"
    exit 1
}
expect_usage_error() { # <what the message names> <arguments...>
    local named="$1"
    shift
    local message
    message=$(timeout 20 "$demo" "$@" --frames 600 2>&1)
    local code=$?
    [ "$code" -eq 1 ] || fail "$* exited with $code, expected 1: $message"
    echo "$message" | grep -qF -- "$named" || fail "$* did not name $named: $message"
    echo "$message" | grep -q "frames per mode" && fail "$* started the run before refusing"
    return 0
}
expect_usage_error "--seed" --seed -1
expect_usage_error "--seed" --seed 18446744073709551616
expect_usage_error "--candidate-margin" --candidate-margin nan
expect_usage_error "--frames" --frames abc  # CLI11's own code for this was 105
expect_usage_error "--mode" --mode sideways
touch not-a-folder
expect_usage_error "--output not-a-folder/report" --output not-a-folder/report
# The world file: unreadable, malformed, a typo'd key, a value out of range, a world too big for the demo
expect_usage_error "--world: missing.json" --world missing.json
echo '{"agents": 8,' >truncated.json
expect_usage_error "--world: truncated.json" --world truncated.json
echo '{"agent": 8}' >typo.json
expect_usage_error 'unknown key "agent"' --world typo.json
echo '{"collision_radius": "far"}' >type.json
expect_usage_error '"collision_radius": expected a number' --world type.json
echo '{"props_per_tile": 5000, "collision_radius": 6}' >huge.json
expect_usage_error "bodies at once" --world huge.json
echo '{"seed": -1}' >seed.json
expect_usage_error '"seed": expected a whole number from 0 to 2^64 - 1' --world seed.json
echo "cairn-demo command line: all checks passed"
