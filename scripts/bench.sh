#!/usr/bin/env bash
# The whole benchmark suite (BENCHMARKS.md) in one command: builds the Release benchmarks, runs
# each one, and writes every figure as rows benchmark,case,metric,value,unit to one CSV, plus the
# median of each over the repetitions (a second CSV, the one BENCHMARKS.md quotes).
#
#   bash scripts/bench.sh [--quick] [--repeat N] [--robots "N1 N2 ..."] [--out DIR]
#
#   --quick    every benchmark briefly, to check that it runs (CI); not figures to quote.
#   --repeat   repetitions of each multi-process case (default 3); medians are over them.
#   --shards   shard counts of the discovery comparison (default "4 8 16")
#   --robots   robot counts of the fleet sweep (default "100 200 250 300 350 400 500"); each count
#              runs the localizer and, in turn, the bare Fast DDS relay (--bare) as its yardstick.
#   --out      output directory (default build/bench): results.csv (every run), medians.csv.
#
# Each multi-process benchmark leases its own DDS domain (tests/support/domain_id.hpp) and uses
# the loopback-only profiles; nothing leaves the machine. Run it on a quiet machine: other load
# shows in every figure.
set -euo pipefail
cd "$(dirname "$0")/.."
quick=0
repeat=3
robots="100 200 250 300 350 400 500"
shards="4 8 16"
out=build/bench
while [ $# -gt 0 ]; do
  case "$1" in
    --quick) quick=1 ;;
    --repeat) repeat="$2"; shift ;;
    --robots) robots="$2"; shift ;;
    --shards) shards="$2"; shift ;;
    --out) out="$2"; shift ;;
    *) echo "bench.sh: unknown option '$1'" >&2; exit 2 ;;
  esac
  shift
done
if [ "$quick" = 1 ]; then
  repeat=1
  robots="5"
  shards="3"
fi

dir=build/release
cmake -S . -B "$dir" -G Ninja -DCMAKE_BUILD_TYPE=Release -DBEACONLOC_WERROR=ON -DBEACONLOC_BUILD_BENCHMARKS=ON >/dev/null
cmake --build "$dir" -j 2 --target beaconloc beaconloc_benchmarks beaconloc_latency beaconloc_fleet_benchmark \
  beaconloc_footprint_benchmark beaconloc_discovery_benchmark
mkdir -p "$out"
csv="$out/results.csv"
rm -f "$csv" "$out/medians.csv"
bin="$dir/benchmarks"
echo "# machine: $(nproc) cores, $(awk '/MemTotal/ {printf "%.0f GiB", $2 / 1048576}' /proc/meminfo)," \
  "$(awk -F': ' '/model name/ {print $2; exit}' /proc/cpuinfo), $(uname -r)" | tee "$out/machine.txt"

# 1. Estimator cost (Google Benchmark): the median of 5 repetitions of each, in microseconds.
echo "== estimator cost"
gbench_args=(--benchmark_repetitions=5 --benchmark_report_aggregates_only=true)
[ "$quick" = 1 ] && gbench_args=(--benchmark_min_time=0.01)
"$bin/beaconloc_benchmarks" "${gbench_args[@]}" --benchmark_out="$out/estimators.json" --benchmark_out_format=json
# Google Benchmark's JSON has one "key": value per line; a benchmark's entry ends with "}".
# (Its CSV writer refuses benchmarks with different counters.) Keeps the median aggregates, or
# every run with --quick.
awk -v quick="$quick" '
  /"name":/ { name = $0; sub(/.*"name": "/, "", name); sub(/",?$/, "", name) }
  /"aggregate_name":/ { aggregate = $0; sub(/.*"aggregate_name": "/, "", aggregate); sub(/",?$/, "", aggregate) }
  /"cpu_time":/ { cpu = $2; sub(/,$/, "", cpu) }
  /"time_unit":/ { unit = $2; gsub(/[",]/, "", unit) }
  /^ *},?$/ && name != "" {
    if (quick == 1 || aggregate == "median") {
      sub(/_median$/, "", name)
      scale = (unit == "ns") ? 1e-3 : (unit == "ms") ? 1e3 : 1
      printf "estimator_cost,%s,cpu_time,%.4g,us\n", name, cpu * scale
    }
    name = ""; aggregate = ""
  }' "$out/estimators.json" > "$out/estimators.rows"
{ echo "benchmark,case,metric,value,unit"; cat "$out/estimators.rows"; } > "$csv"
rm -f "$out/estimators.rows"

# 2. End-to-end latency against the raw DDS hop, shared memory and UDP loopback, each without and
#    with DDS Security, interleaved in one run (benchmarks/latency/main.cpp says what is measured,
#    CPU per sample included); it writes its own medians (e2e_latency).
echo "== end-to-end latency"
if [ "$quick" = 1 ]; then
  "$bin/latency/beaconloc_latency" --security both --duration-s 3 --warmup-s 2 --hop-duration-s 2 --b2b-hop-s 1 \
    --csv "$csv"
else
  "$bin/latency/beaconloc_latency" --security both --repeat "$repeat" --duration-s 40 --csv "$csv"
fi

# 3. Robots served by one localizer process, and by the bare Fast DDS relay standing in for it
#    (the middleware's own cost of the same samples), in turn.
echo "== robots per machine"
for n in $robots; do
  for ((i = 1; i <= repeat; i++)); do
    for bare in "" --bare; do
      if [ "$quick" = 1 ]; then
        "$bin/fleet/beaconloc_fleet_benchmark" --robots "$n" --warmup-s 2 --window-s 3 $bare --csv "$csv"
      else
        "$bin/fleet/beaconloc_fleet_benchmark" --robots "$n" --warmup-s 5 --window-s 10 $bare --csv "$csv"
      fi
    done
  done
done

# 4. Memory of each participant and the localizer's start to first pose.
echo "== memory and start-up"
if [ "$quick" = 1 ]; then
  "$bin/footprint/beaconloc_footprint_benchmark" --runs 1 --settle-s 3 --csv "$csv"
else
  "$bin/footprint/beaconloc_footprint_benchmark" --runs 5 --csv "$csv"
fi

# 5. Discovery across hosts (network namespaces, root only): simple discovery against two
#    discovery servers, side by side in each run.
echo "== discovery across hosts"
if [ "$(id -u)" -ne 0 ]; then
  echo "bench.sh: discovery across hosts skipped: network namespaces need root"
else
  for ((i = 1; i <= repeat; i++)); do
    if [ "$quick" = 1 ]; then
      "$bin/discovery/beaconloc_discovery_benchmark" --shards "$shards" --window-s 4 --steady-s 2 --csv "$csv"
    else
      "$bin/discovery/beaconloc_discovery_benchmark" --shards "$shards" --window-s 10 --steady-s 5 --csv "$csv"
    fi
  done
fi

# Medians over the repetitions of each benchmark,case,metric (rows in the order first seen).
awk -F, 'NR > 1 { key = $1 "," $2 "," $3; if (!(key in unit)) { order[++n] = key; unit[key] = $5 }
                  count[key]++; value[key, count[key]] = $4 }
         END {
           print "benchmark,case,metric,median,unit,runs"
           for (i = 1; i <= n; i++) {
             k = order[i]; m = count[k]
             for (a = 1; a <= m; a++) v[a] = value[k, a]
             for (a = 2; a <= m; a++) { x = v[a]; b = a - 1; while (b > 0 && v[b] + 0 > x + 0) { v[b + 1] = v[b]; b-- } v[b + 1] = x }
             med = (m % 2) ? v[(m + 1) / 2] : (v[m / 2] + v[m / 2 + 1]) / 2
             print k "," med "," unit[k] "," m
           }
         }' "$csv" > "$out/medians.csv"
echo "bench.sh: every run in $csv, medians in $out/medians.csv"
