#!/usr/bin/env bash
# The fleet benchmark (BENCHMARKS.md section 3) of two commits side by side in one run, with the
# bare Fast DDS relay as the yardstick (issue 19: "each lever measured on its own"; "the bare
# Fast DDS cost of the same sample rates measured in the same run"). Builds the fleet benchmark
# and `beaconloc` (Release) at BASE in a git worktree under build/compare/, and at the working
# tree in build/release, then runs, ROUNDS rounds for each robot count, each round in this order:
# BASE's localizer, this tree's localizer, this tree's --bare relay. Prints, per robot count and
# side, the median of each figure over the rounds and how many rounds were in real time.
#
#   bash scripts/fleet-compare.sh [BASE] [ROUNDS] [ROBOTS]
#
#   BASE     the commit to compare with (default HEAD~1).
#   ROUNDS   default 3.
#   ROBOTS   robot counts, quoted (default "300").
# Writes every run's rows to build/compare/<BASE>-fleet-<time>/results.csv, and each run's output
# beside it. Each run leases its own DDS domain and uses the loopback-only profile. Run it on a
# quiet machine.
set -euo pipefail
cd "$(dirname "$0")/.."
base=${1:-HEAD~1}
rounds=${2:-3}
robots=${3:-300}
[[ "$rounds" =~ ^[1-9][0-9]*$ ]] || { echo "fleet-compare: ROUNDS must be a positive number, not '$rounds'" >&2; exit 2; }
. scripts/compare-trees.sh
build_both_trees "$base" beaconloc beaconloc_fleet_benchmark
before="$tree/build/benchmarks/fleet/beaconloc_fleet_benchmark"
after=build/release/benchmarks/fleet/beaconloc_fleet_benchmark
out=build/compare/$base_sha-fleet-$(date +%Y%m%dT%H%M%S)
mkdir -p "$out"
csv="$out/results.csv"
for n in $robots; do
  for ((i = 1; i <= rounds; i++)); do
    for side in before after bare; do
      echo "== $n robots, round $i/$rounds: $side"
      case $side in
        before) "$before" --robots "$n" --warmup-s 5 --window-s 10 --csv "$out/before.csv" ;;
        after) "$after" --robots "$n" --warmup-s 5 --window-s 10 --csv "$out/after.csv" ;;
        bare) "$after" --robots "$n" --warmup-s 5 --window-s 10 --bare --csv "$out/bare.csv" ;;
      esac > "$out/$side-$n-$i.log"
      grep -h "logs kept in" "$out/$side-$n-$i.log" || true
    done
  done
done
for side in before after bare; do sed "s/^/$side,/" "$out/$side.csv"; done > "$csv"
echo "# $(nproc) cores; before = $base_sha, after = working tree of $(git rev-parse --short=10 HEAD)," \
  "bare = after --bare; $rounds rounds, each before, after, bare; medians over the rounds; every run in $out"
awk -F, '
  $3 == "case" { next }
  { side = $1; n = $3; sub(/robots=/, "", n); metric = $4; key = n SUBSEP side SUBSEP metric
    c = ++count[key]; v[key, c] = $5
    if (!(n in seen_n)) { seen_n[n] = 1; ns[++nn] = n } }
  function median(key,    m, a, b, x, w) {
    m = count[key]; if (m == 0) return "-"
    for (a = 1; a <= m; a++) w[a] = v[key, a]
    for (a = 2; a <= m; a++) { x = w[a]; b = a - 1; while (b > 0 && w[b] + 0 > x + 0) { w[b + 1] = w[b]; b-- } w[b + 1] = x }
    return (m % 2) ? w[(m + 1) / 2] : (w[m / 2] + w[m / 2 + 1]) / 2
  }
  function sum(key,    a, t) { t = 0; for (a = 1; a <= count[key]; a++) t += v[key, a]; return t }
  END {
    printf "%-7s %-7s %9s %12s %10s %12s %10s %9s %9s %9s\n", "robots", "side", "real time", "localizer %", "per robot",
      "poses recv", "age p99", "feeder %", "decoder %", "sink %"
    for (i = 1; i <= nn; i++) {
      n = ns[i]
      split("before after bare", sides, " ")
      for (s = 1; s <= 3; s++) {
        side = sides[s]; k = n SUBSEP side SUBSEP
        if (count[k "real_time"] == 0) continue
        printf "%-7s %-7s %5d of %d %12.1f %10.3f %12.3f %10.1f %9.1f %9.1f %9.1f\n", n, side, sum(k "real_time"),
          count[k "real_time"], median(k "localizer_cpu"), median(k "localizer_cpu_per_robot"),
          median(k "odometry_poses_received_ratio"), median(k "pose_age_p99"), median(k "feeder_cpu"),
          median(k "decoder_cpu"), median(k "sink_cpu")
      }
      b = median(n SUBSEP "bare" SUBSEP "localizer_cpu"); a = median(n SUBSEP "after" SUBSEP "localizer_cpu")
      if (b != "-" && a != "-" && b > 0) printf "%-7s localizer / bare Fast DDS: %.2f\n", n, a / b
    }
  }' "$csv"
