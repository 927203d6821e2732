#!/usr/bin/env bash
# The estimator benchmarks of two commits side by side in one run (issue 14: "no estimator gets
# slower"). Builds beaconloc_benchmarks (Release) at BASE in a git worktree under build/compare/,
# and at the working tree in build/release, then runs the two binaries in turn, ROUNDS rounds,
# each round 3 repetitions of every benchmark, so that both see the same machine load; prints the
# median CPU time of each benchmark over all rounds, before and after, and their ratio.
#
#   bash scripts/bench-compare.sh [BASE] [ROUNDS] [FILTER]
#
#   BASE     the commit to compare with (default HEAD~1).
#   ROUNDS   default 4.
#   FILTER   a --benchmark_filter regex (default: all). Benchmarks only one side has are listed
#            with "-" on the other.
# Needs nothing beyond the packages scripts/install-deps.sh installs.
set -euo pipefail
cd "$(dirname "$0")/.."
base=${1:-HEAD~1}
rounds=${2:-4}
filter=${3:-.}
. scripts/compare-trees.sh
build_both_trees "$base" beaconloc_benchmarks
before="$tree/build/benchmarks/beaconloc_benchmarks"
after=build/release/benchmarks/beaconloc_benchmarks
out=build/compare/$base_sha-results
rm -rf "$out"
mkdir -p "$out"
for ((i = 1; i <= rounds; i++)); do
  for side in before after; do
    bin=$before
    [ "$side" = after ] && bin=$after
    echo "== round $i/$rounds: $side"
    "$bin" --benchmark_filter="$filter" --benchmark_repetitions=3 --benchmark_format=json \
      --benchmark_out="$out/$side-$i.json" --benchmark_out_format=json >/dev/null
  done
done
# Every repetition's cpu_time (us) per benchmark and side, then the medians side by side.
for side in before after; do
  cat "$out/$side"-*.json | awk -v side="$side" '
    /"name":/ { name = $0; sub(/.*"name": "/, "", name); sub(/",?$/, "", name) }
    /"run_type":/ { type = $0; sub(/.*"run_type": "/, "", type); sub(/",?$/, "", type) }
    /"cpu_time":/ { cpu = $2; sub(/,$/, "", cpu) }
    /"time_unit":/ { unit = $2; gsub(/[",]/, "", unit) }
    /^ *},?$/ && name != "" {
      if (type == "iteration") {
        scale = (unit == "ns") ? 1e-3 : (unit == "ms") ? 1e3 : 1
        printf "%s %s %.6g\n", side, name, cpu * scale
      }
      name = ""; type = ""
    }'
done > "$out/runs.txt"
echo "# $(nproc) cores; before = $base_sha, after = working tree of $(git rev-parse --short=10 HEAD);" \
  "$rounds rounds x 3 repetitions, alternating"
awk '
  { key = $2; if (!(key in seen)) { seen[key] = 1; order[++n] = key }
    c = ++count[$1, key]; v[$1, key, c] = $3 }
  function median(side, key,    m, a, b, x, w) {
    m = count[side, key]; if (m == 0) return ""
    for (a = 1; a <= m; a++) w[a] = v[side, key, a]
    for (a = 2; a <= m; a++) { x = w[a]; b = a - 1; while (b > 0 && w[b] > x) { w[b + 1] = w[b]; b-- } w[b + 1] = x }
    return (m % 2) ? w[(m + 1) / 2] : (w[m / 2] + w[m / 2 + 1]) / 2
  }
  END {
    printf "%-60s %12s %12s %8s\n", "benchmark (median cpu time, us)", "before", "after", "ratio"
    for (i = 1; i <= n; i++) {
      k = order[i]; b = median("before", k); a = median("after", k)
      ratio = (b != "" && a != "" && b > 0) ? sprintf("%.2f", a / b) : "-"
      printf "%-60s %12s %12s %8s\n", k, (b == "" ? "-" : sprintf("%.4g", b)), (a == "" ? "-" : sprintf("%.4g", a)), ratio
    }
  }' "$out/runs.txt" | tee "$out/medians.txt"
