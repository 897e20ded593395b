#!/bin/sh
# A bounded libFuzzer run of the trip frame parser and request handler:
#   fuzz.sh FUZZER SECONDS
# Seeds a fresh corpus in a temporary folder (so that two runs at once do not
# share one), runs for SECONDS, and fails on any crash or sanitizer report;
# a crashing input is kept as fuzz-crash-* in the current folder.
set -u
fuzzer=$1 seconds=$2
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT INT TERM
mkdir "$tmp/corpus"
printf '\002\061 ping\003' > "$tmp/corpus/ping"
printf '\002\061 open base\003\002\062 base goto 1 2\003' > "$tmp/corpus/goto"
printf '\002\061 open speech\003\002\062 speech say \020B\020C\020P\003' \
    > "$tmp/corpus/say"
printf '\002\061 open sonar\003\002\062 sonar read\003\002\063 sonar stream on\003' \
    > "$tmp/corpus/sonar"
# (the first byte says where the reads are cut: here 'A', after 15 bytes)
printf 'A\002\061 open base\003\002\062 base goto 1 2\003\002\063 base await\003' \
    > "$tmp/corpus/await"
printf 'x\002\061 \020Z\003\002\061 pi\002\062 who\003' > "$tmp/corpus/bad"
"$fuzzer" -max_total_time="$seconds" -max_len=2048 -print_final_stats=1 \
    -artifact_prefix=fuzz-crash- "$tmp/corpus" > "$tmp/log" 2>&1
status=$?
grep -E '^Done|ERROR|SUMMARY' "$tmp/log"
exit $status
