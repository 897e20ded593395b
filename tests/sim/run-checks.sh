#!/bin/sh
# Run the simulator's C tests and add up their "N passed, N failed" lines;
# the last line printed is the total, for the top Makefile.
#   run-checks.sh BUILD-DIR B14 [EXTRA-COMMAND ...]
# Each EXTRA-COMMAND (e.g. the bounded fuzz run) is one more test case.
set -u
build=$1 b14=$2
shift 2
top=$(cd "$(dirname "$0")/../.." && pwd)
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT INT TERM
passed=0 failed=0

count() {   # add the summary line of a test's output
    line=$(tail -n 1 "$tmp/out")
    p=$(echo "$line" | sed -n 's/^\([0-9]*\) passed, \([0-9]*\) failed$/\1/p')
    f=$(echo "$line" | sed -n 's/^\([0-9]*\) passed, \([0-9]*\) failed$/\2/p')
    if [ -z "$p" ]; then p=0 f=1; echo "sim: $1 ended without a summary"; fi
    passed=$((passed + p)) failed=$((failed + f))
    echo "sim: $1: $line"
}

for t in test_frame test_world; do
    "$build/$t" > "$tmp/out"
    count "$t"
done
mkdir "$tmp/trip"
"$build/test_trip" "$b14" "$("$top/tools/free-port-base")" "$tmp/trip" > "$tmp/out"
count test_trip
for extra in "$@"; do
    if sh -c "$extra" > "$tmp/extra.log" 2>&1; then
        passed=$((passed + 1)); echo "sim: ok: $extra"
    else
        failed=$((failed + 1)); echo "sim: FAIL: $extra"; tail -n 20 "$tmp/extra.log"
    fi
done
echo "$passed passed, $failed failed"
[ "$failed" -eq 0 ]
