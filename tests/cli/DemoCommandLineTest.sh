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
echo "cairn-demo command line: all checks passed"
