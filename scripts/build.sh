#!/usr/bin/env bash
# Configures and builds one configuration: bash scripts/build.sh [Release|Debug|Asan]
# into build/release, build/debug or build/asan. Asan is Debug (Eigen's assertions on) at -O1,
# as the sanitizers recommend, with AddressSanitizer and UndefinedBehaviorSanitizer
# (BEACONLOC_SANITIZE, see CMakeLists.txt) and without the benchmarks; run its tests with
# scripts/sanitizers.env in the environment. Two compile jobs: ~330 MB each, sized for 2 cores.
set -euo pipefail
cd "$(dirname "$0")/.."
type="${1:-Release}"
case "$type" in
  Release) dir=build/release ;;
  Debug) dir=build/debug ;;
  Asan) dir=build/asan ;;
  *) echo "build.sh: unknown build type '$type' (Release, Debug or Asan)" >&2; exit 2 ;;
esac
if [ "$type" = Asan ]; then
  cmake -S . -B "$dir" -G Ninja -DCMAKE_BUILD_TYPE=Debug -DBEACONLOC_SANITIZE=ON -DBEACONLOC_BUILD_BENCHMARKS=OFF \
    -DBEACONLOC_WERROR=ON >/dev/null
else
  # Configured for /usr: the Debian packages are made of this build (cpack -G DEB,
  # cmake/BeaconlocInstall.cmake; docs/deployment.md). Install it anywhere else with
  # cmake --install build/release --prefix DIR.
  cmake -S . -B "$dir" -G Ninja -DCMAKE_BUILD_TYPE="$type" -DBEACONLOC_WERROR=ON -DCMAKE_INSTALL_PREFIX=/usr >/dev/null
fi
cmake --build "$dir" -j 2
