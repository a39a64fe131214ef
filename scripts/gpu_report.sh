#!/usr/bin/env bash
# The GPU figures of the README in one run, for a machine with a GPU (the device tool's H100): the benchmark
# at 1920x1080 over every model (with the ray-tracing-pipeline peer and wrong pixels against the exact
# reference), the local-light benchmark (sun, spot and point lights inside two buildings), the hard cases, the binning matrix, the accuracy report and a 1080p render of the built-in
# scene. Writes nine files into $OUT (default out/gpu): each report's output (stderr included), and the
# render's frame.json, preview and occupancy images. HRTS_BIN names a prebuilt host_demo, HRTS_MODELS the
# models folder.
set -uo pipefail
bin=${HRTS_BIN:-target/release/host_demo}
out=${OUT:-out/gpu}
mkdir -p "$out"
status=0
run() {
    local name=$1
    shift
    echo "== $name: $*"
    local start=$SECONDS
    "$bin" "$@" >"$out/$name.txt" 2>&1 || { status=1; echo "   FAILED: $(tail -n 3 "$out/$name.txt")"; }
    echo "   $((SECONDS - start)) s"
}
render=$(mktemp -d)
run render render --width 1920 --height 1080 --frames 30 --out "$render"
cp "$render/frame.json" "$render/preview.png" "$render/occupancy.png" "$out/" 2>/dev/null
run bench bench --frames 30
run bench_lights bench --lights --point-lights 16 --frames 30
run hardcases hardcases
run tiers tiers
run accuracy accuracy --width 1920 --height 1080
exit $status
