#!/usr/bin/env bash
# Installs every package beaconloc builds and tests with, from Debian 12's archive.
set -euo pipefail
SUDO=""
if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update
$SUDO apt-get install -y --no-install-recommends \
  ca-certificates cmake g++ ninja-build make \
  libfastrtps-dev libfastcdr-dev libtinyxml2-dev fastddsgen \
  libeigen3-dev libcli11-dev libyaml-cpp-dev \
  libgtest-dev libgmock-dev libbenchmark-dev \
  cyclonedds-dev cyclonedds-tools \
  fastdds-tools iproute2 \
  openssl libssl-dev \
  libsqlite3-dev socat python3 python3-yaml \
  dpkg-dev file \
  clang libclang-rt-14-dev llvm
# libsqlite3-dev (beaconloc record writes rosbag2's sqlite3 storage), socat (the serial gateway's
# tests: linked pseudo-terminals), python3 with python3-yaml (tests/tools/check_rosbag2.py, a reader
# of those bags that shares no code with the writer).
# dpkg-dev (dpkg-shlibdeps) and file: CPack's Debian packages find their dependencies from the
# executable's shared libraries (cmake/BeaconlocInstall.cmake, integration.StagedInstall).
# openssl (scripts/deployment-keys.sh: a secured deployment's keys) and libssl-dev (dds/security.cpp
# checks an enclave's certificates before Fast DDS does; Fast DDS's security plugins link it too).
# fastdds-tools (fast-discovery-server) and iproute2 (ip netns): the multi-host tests, whose hosts
# are network namespaces finding each other through two discovery servers (tests/multihost).
# clang, libclang-rt-14-dev (libFuzzer, ASan and UBSan runtimes) and llvm (llvm-symbolizer, for
# readable reports): the fuzz targets, scripts/fuzz.sh.
