#!/usr/bin/env bash
# The noise a set of recordings of one vehicle and one ranging sensor fits best, without ground
# truth (docs/replay-odometry-noise.md): replays each recording with range_ekf for every triple
# (range sigma, k_v, N) of the grid and prints range_ekf's range_innovation_nll_nats (the mean negative
# log-likelihood of the ranges' innovations, nats per range, gated ones counted at the gate) for
# each recording, and their mean, the criterion: each recording counts alike, whatever its
# length. The smallest mean is marked (bold). The position RMS against ground truth is printed
# beside it for the reader only; the choice does not look at it.
#
#   bash scripts/replay-noise-fit.sh --sigma "S1 S2 ..." --kv "K1 K2 ..." --arw "N1 N2 ..." RECORDING... \
#     [-- RUN ARGS...]
#
# S: the ranges' sigma (--range-sigma-m; without --sigma, the one RUN ARGS give, for a sensor
# that states it), K: the odometry's --replay-odometry-k-v, N: its --replay-heading-arw (read
# only for a recording without wheels).
# RUN ARGS are the rest of the `beaconloc run` command (decoder limits, estimator parameters),
# the same for every recording. Each run uses the loopback-only profile and a DDS domain of its
# own. Example (the CMU Plaza lawn mower, docs/replay-odometry-noise.md):
#
#   bash scripts/replay-noise-fit.sh --sigma "0.5 0.6 0.7" --kv "0.0005 0.001 0.002" --arw "0.01 0.014 0.02" \
#     ../shared/datasets/cmu_plaza_gpslam/replay/plaza1 ../shared/datasets/cmu_plaza_gpslam/replay/plaza2 \
#     -- --max-range-m 150 --param range_calibration=1
set -euo pipefail
sigmas=""
kvs=""
arws=""
recordings=()
run_args=()
while [ $# -gt 0 ]; do
  case "$1" in
    --sigma) sigmas="$2"; shift 2 ;;
    --kv) kvs="$2"; shift 2 ;;
    --arw) arws="$2"; shift 2 ;;
    --) shift; run_args=("$@"); break ;;
    # Named from where the script was called, before it moves to the repository.
    *) recordings+=("$(realpath -m -- "$1")"); shift ;;
  esac
done
cd "$(dirname "$0")/.."
B=./build/release/plugins/beaconloc
if [ -z "$kvs" ] || [ -z "$arws" ] || [ ${#recordings[@]} -eq 0 ]; then
  echo "usage: replay-noise-fit.sh [--sigma \"S...\"] --kv \"K...\" --arw \"N...\" RECORDING... [-- RUN ARGS...]" >&2
  exit 2
fi
[ -x "$B" ] || { echo "replay-noise-fit.sh: build first (bash scripts/build.sh)" >&2; exit 2; }
given_sigma=""
for a in "${run_args[@]}"; do
  if [ "$a" = "--range-sigma-m" ]; then given_sigma=yes; fi
done
if [ -n "$sigmas" ] && [ -n "$given_sigma" ]; then
  echo "replay-noise-fit.sh: --sigma and a --range-sigma-m in RUN ARGS: give one" >&2
  exit 2
fi
# "given": the sigma RUN ARGS give (or the decoder's default).
[ -n "$sigmas" ] || sigmas="given"
# A DDS domain of its own (not 0, where other processes may run): 100-199 by process id.
domain=$((100 + $$ % 100))
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT

printf '| range sigma (m) | k_v (m) | N (rad/sqrt(s)) |'
for r in "${recordings[@]}"; do printf ' %s nll | %s RMS (m) |' "$(basename "$r")" "$(basename "$r")"; done
printf ' mean nll |\n|---|---|---|'
for _ in "${recordings[@]}"; do printf -- '---|---|'; done
printf -- '---|\n'
best=""
best_index=""
lines=()
means=()
for sigma in $sigmas; do
 for kv in $kvs; do
  for arw in $arws; do
    line="| $sigma | $kv | $arw |"
    sum=0
    for r in "${recordings[@]}"; do
      log="$out/run.log"
      sigma_args=()
      [ "$sigma" = given ] || sigma_args=(--range-sigma-m "$sigma")
      if ! "$B" run --domain "$domain" --replay "$r" "${sigma_args[@]}" --replay-odometry-k-v "$kv" \
        --replay-heading-arw "$arw" "${run_args[@]}" \
        --out "$out/run" >"$log" 2>&1; then
        echo "replay-noise-fit.sh: the run of $r failed:" >&2
        tail -5 "$log" >&2
        exit 1
      fi
      nll=$(grep -o 'range_innovation_nll_nats [-0-9.e+]*' "$log" | tail -1 | cut -d' ' -f2 || true)
      rms=$(grep '^poses' "$log" | sed -n 's/.*position RMS \([0-9.]*\) m.*/\1/p' || true)
      if [ -z "$nll" ]; then
        echo "replay-noise-fit.sh: $r gave no range_innovation_nll_nats (no range fused): not a fit" >&2
        exit 1
      fi
      line="$line $nll | ${rms:-n/a} |"
      sum=$(awk -v a="$sum" -v b="$nll" 'BEGIN { printf "%.10f", a + b }')
    done
    mean=$(awk -v s="$sum" -v n="${#recordings[@]}" 'BEGIN { printf "%.5f", s / n }')
    lines+=("$line")
    means+=("$mean")
    if [ -z "$best" ] || awk -v a="$mean" -v b="$best" 'BEGIN { exit !(a < b) }'; then
      best="$mean"
      best_index=$((${#lines[@]} - 1))
    fi
  done
 done
done
for i in "${!lines[@]}"; do
  if [ "$i" = "$best_index" ]; then echo "${lines[$i]} **${means[$i]}** |"; else echo "${lines[$i]} ${means[$i]} |"; fi
done
