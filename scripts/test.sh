#!/usr/bin/env bash
# The test suite: builds Release and Debug, runs every test on Release (unit, multi-process
# integration on loopback, CLI) and the unit tests again on Debug (Eigen's assertions on).
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/build.sh Debug
ctest --test-dir build/debug -R '^unit\.' -j 2 --output-on-failure
bash scripts/build.sh Release
ctest --test-dir build/release -j 2 --output-on-failure
