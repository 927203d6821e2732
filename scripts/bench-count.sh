#!/usr/bin/env bash
# Instructions and simulated L1 data-cache misses per timed step of the estimator benchmarks,
# before (BASE, built by scripts/bench-compare.sh in build/compare/) and after (build/release),
# counted by callgrind: figures that do not move with the machine's load, beside the timings of
# bench-compare.sh. Needs valgrind (Debian package valgrind), which scripts/install-deps.sh does
# not install: the suite does not need it.
#
#   bash scripts/bench-count.sh BASE FILTER...     e.g.  bash scripts/bench-count.sh 5822849 'BM_Duhl_Step/6$'
#
# Each FILTER is one --benchmark_filter; it should select one benchmark. Prints, per filter and
# side, the calls of the timed step (bench::run_step) and its instructions (Ir) and D1 read and
# write misses per call.
set -euo pipefail
cd "$(dirname "$0")/.."
base_sha=$(git rev-parse --short=10 "$1^{commit}")
shift
before=build/compare/$base_sha/build/benchmarks/beaconloc_benchmarks
after=build/release/benchmarks/beaconloc_benchmarks
for bin in "$before" "$after"; do
  [ -x "$bin" ] || { echo "bench-count: $bin is missing: run scripts/bench-compare.sh $base_sha first" >&2; exit 2; }
done
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
printf '%-44s %-6s %8s %10s %10s %10s\n' benchmark side calls Ir/call D1mr/call D1mw/call
for filter in "$@"; do
  for side in before after; do
    bin=$before
    [ "$side" = after ] && bin=$after
    valgrind --tool=callgrind --cache-sim=yes --collect-atstart=no \
      --toggle-collect='beaconloc::bench::run_step*' --callgrind-out-file="$out/cg.out" \
      "$bin" --benchmark_filter="$filter" --benchmark_min_time=0.02 >/dev/null 2>&1
    # run_step's line in the calling tree: inclusive Ir Dr Dw I1mr D1mr D1mw ... (Nx).
    callgrind_annotate --inclusive=yes --tree=calling "$out/cg.out" 2>/dev/null | grep 'run_step.*x)' | head -1 |
      awk -v f="$filter" -v side="$side" '{
        gsub(/,/, "", $1); gsub(/,/, "", $9); gsub(/,/, "", $11)
        n = $(NF - 1); gsub(/[(x),]/, "", n)
        printf "%-44s %-6s %8d %10.0f %10.1f %10.1f\n", f, side, n, $1 / n, $9 / n, $11 / n }'
  done
done
