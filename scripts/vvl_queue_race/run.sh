#!/bin/bash
# Builds repro.c and runs PROCS copies of it at once (CPU contention makes the layer's race likely on a
# 2-core machine) with the options given as VAR=value arguments; prints how many crashed.
# Usage: scripts/vvl_queue_race/run.sh [PROCS] [VAR=value ...]
# e.g.   scripts/vvl_queue_race/run.sh 4 PASSES=64 TIMESTAMPS=0 ITERATIONS=100000
set -u
here=$(cd "$(dirname "$0")" && pwd)
procs=${1:-4}
shift || true
out=$(mktemp -d)
cc -O1 -g -o "$out/repro" "$here/repro.c" -lvulkan || exit 2
for i in $(seq 1 "$procs"); do
    (env "$@" "$out/repro" > "$out/$i.log" 2>&1; echo "exit $?" >> "$out/$i.log") &
done
wait
crashed=0
for i in $(seq 1 "$procs"); do
    status=$(tail -n 1 "$out/$i.log")
    [ "$status" = "exit 0" ] || crashed=$((crashed + 1))
    echo "process $i: $status $(grep -h -m1 -e 'malloc' -e 'corrupt' -e 'free()' -e 'bad_alloc' "$out/$i.log")"
done
echo "$crashed of $procs processes crashed ($*); logs in $out"
