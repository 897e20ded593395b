#!/bin/sh
# Run the dual-sonar demo (demo.scm) on the Tulane lab and leave its trace
# in the SVG file named by $1.  Starts sim/b14 on free ports, stops it with
# SIGTERM so that it writes the trace, and leaves no process behind.
set -eu
here=$(cd "$(dirname "$0")" && pwd)
top=$(cd "$here/.." && pwd)
out=$1
tmp=$(mktemp -d)
pid=
trap 'if [ -n "$pid" ]; then kill "$pid" 2>/dev/null || true; fi; rm -rf "$tmp"' EXIT INT TERM
base=$("$top/tools/free-port-base")
"$here/b14" "$top/examples/tulane-lab.scm" --port-base "$base" --speed 5 \
    --trace "$out" --lock-dir "$tmp/locks" > "$tmp/out" &
pid=$!
i=0
until grep -q '^b14: ready' "$tmp/out"; do
    i=$((i + 1)); [ "$i" -lt 200 ] || { echo "demo: b14 did not start" >&2; exit 1; }
    sleep 0.05
done
MURDOCH_PORT_BASE=$base "$top/tools/chibi" "$here/demo.scm"
kill -TERM "$pid"
wait "$pid"
pid=
echo "demo: trace in $out"
