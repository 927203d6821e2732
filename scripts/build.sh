#!/usr/bin/env bash
# Configures and builds one configuration: bash scripts/build.sh [Release|Debug]
# into build/release or build/debug. Two compile jobs: ~330 MB each, sized for 2 cores.
set -euo pipefail
cd "$(dirname "$0")/.."
type="${1:-Release}"
case "$type" in
  Release) dir=build/release ;;
  Debug) dir=build/debug ;;
  *) echo "build.sh: unknown build type '$type' (Release or Debug)" >&2; exit 2 ;;
esac
cmake -S . -B "$dir" -G Ninja -DCMAKE_BUILD_TYPE="$type" -DBEACONLOC_WERROR=ON >/dev/null
cmake --build "$dir" -j 2
