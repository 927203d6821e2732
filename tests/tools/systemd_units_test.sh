#!/usr/bin/env bash
# integration.SystemdUnits: the systemd units of deploy/systemd, as generated for installation.
#   (a) Wherever systemd-analyze exists: `systemd-analyze verify` on every unit, its templates and
#       a robot's instances, with the build's binary in ExecStart (verify checks it is executable);
#       any finding fails. It needs no running systemd.
#   (b) Where a systemd user manager can be used (PID 1 is systemd and `systemctl --user` answers):
#       the units as user units (in $XDG_RUNTIME_DIR/systemd/user, removed at the end) with the
#       build's binary and a test configuration (loopback profile, a leased domain id): the robot's
#       target starts the four participants, which localize (a monitor hears poses through the
#       hardened units' /dev/shm); a participant killed with SIGKILL is restarted; the target's stop
#       leaves every unit inactive after a clean exit (status 0) and none of their /dev/shm files.
#       Never root, never the system manager, never /etc.
# Either part that cannot run says why; when neither can, the test exits 77 (ctest: skipped).
#
# usage: systemd_units_test.sh UNITS_DIR BUILD_BINARY WORK_DIR
#   UNITS_DIR     the generated units (<build>/deploy/systemd), which name the installed binary
#   BUILD_BINARY  the build's beaconloc, substituted for the installed one in ExecStart
#   WORK_DIR      a directory of the build tree for this test's files (not under /tmp: the units'
#                 PrivateTmp= would hide a configuration there)
set -u
units_dir=$1 binary=$2 work=$3

participants=(gateway decoder localizer bridge)
restart_sec=2  # the units' RestartSec=
fail() { echo "FAIL: $*"; exit 1; }

[ -x "$binary" ] || fail "no executable $binary"
for f in "${participants[@]/#/beaconloc-}"; do
  [ -f "$units_dir/$f@.service" ] || fail "no $units_dir/$f@.service (deploy/CMakeLists.txt generates it)"
done
[ -f "$units_dir/beaconloc@.target" ] || fail "no $units_dir/beaconloc@.target"
# The installed binary the units name (${CMAKE_INSTALL_FULL_BINDIR}/beaconloc), to be replaced.
installed_binary=$(sed -n 's/^ExecStart=\([^ ]*\) decoder .*/\1/p' "$units_dir/beaconloc-decoder@.service")
[ -n "$installed_binary" ] || fail "no 'ExecStart=BINARY decoder ...' in $units_dir/beaconloc-decoder@.service"

rm -rf "$work"
mkdir -p "$work"

# The generated units with the build's binary in ExecStart; anything else as installed.
copy_units() {  # copy_units DIR [extra sed expressions...]
  local dir=$1
  shift
  mkdir -p "$dir"
  for f in "$units_dir"/beaconloc-*@.service "$units_dir"/beaconloc@.target; do
    sed -e "s|^ExecStart=$installed_binary |ExecStart=$binary |" "$@" "$f" >"$dir/$(basename "$f")"
  done
}

# ---- (a) systemd-analyze verify ----------------------------------------------------------------
verify_ran=0 verify_reason=
if ! command -v systemd-analyze >/dev/null; then
  verify_reason="systemd-analyze is not installed (Debian: package systemd)"
else
  copy_units "$work/verify"
  targets=()
  for p in "${participants[@]}"; do
    targets+=("$work/verify/beaconloc-$p@.service" "$work/verify/beaconloc-$p@robot1.service")
  done
  targets+=("$work/verify/beaconloc@robot1.target")
  # --man=no: the units document a file, not a man page. Warnings ("Unknown key", "Invalid device
  # rights") leave verify's exit status 0: any output at all is a finding.
  echo "(a) systemd-analyze verify --man=no: ${#targets[@]} units (templates and robot1's instances)"
  findings=$(systemd-analyze verify --man=no "${targets[@]}" 2>&1)
  status=$?
  if [ $status -ne 0 ] || [ -n "$findings" ]; then
    echo "$findings"
    fail "systemd-analyze verify: exit status $status, findings above"
  fi
  echo "(a) passed: no findings ($(systemd-analyze --version | head -n 1))"
  verify_ran=1
fi

# ---- (b) start, restart, stop under a systemd user manager -------------------------------------
manager_reason=
pid1=$(cat /proc/1/comm 2>/dev/null || echo unknown)
if [ "$pid1" != systemd ]; then
  manager_reason="systemd is not PID 1 (PID 1 is $pid1): the units' start/restart/stop not run"
elif ! command -v systemctl >/dev/null; then
  manager_reason="no systemctl: the units' start/restart/stop not run"
elif [ "$(id -u)" -eq 0 ]; then
  manager_reason="run as root: this part uses a user manager only, never the system's"
  manager_reason+=" (the units' start/restart/stop not run)"
elif [ -z "${XDG_RUNTIME_DIR:-}" ] || ! systemctl --user show-environment >/dev/null 2>&1; then
  manager_reason="no systemd user manager answers (systemctl --user; XDG_RUNTIME_DIR='${XDG_RUNTIME_DIR:-}')"
  manager_reason+=": the units' start/restart/stop not run"
fi

if [ -n "$manager_reason" ]; then
  if [ $verify_ran -eq 0 ]; then
    echo "SKIPPED: (a) $verify_reason; (b) $manager_reason"
    exit 77
  fi
  echo "(b) SKIPPED: $manager_reason"
  exit 0
fi

# A DDS domain id of our own, held until exit.
. "$(dirname "${BASH_SOURCE[0]}")/domain_lease.sh"
lease_domain || fail "no free DDS domain id in 1..200"

robot="systemdtest$$"
etc="$work/etc"
mkdir -p "$etc"
cat >"$etc/$robot.yaml" <<EOF
/**:
  ros__parameters:
    domain: $domain
    participant-profile: beaconloc.loopback
    robot: $robot
gateway:
  ros__parameters:
    duration-s: 0
EOF

# As user units: settings only the system manager can apply go (switching to the user beaconloc,
# the capability bounding set, the device cgroup, ProtectProc=), so do the system targets
# (network-online.target, multi-user.target) and the state directory (the test configuration
# names no calibration file). The configuration moves from /etc/beaconloc to the test's. A
# build tree under /home stays readable: ProtectHome=read-only. The sandboxing settings that
# remain need unprivileged user namespaces in a user manager (Debian 12: on by default).
copy_units "$work/units" \
  -e "s|/etc/beaconloc/|$etc/|g" \
  -e '/^\(User\|Group\|CapabilityBoundingSet\|DevicePolicy\|DeviceAllow\|ProtectProc\|StateDirectory\)=/d' \
  -e '/^\(Wants\|After\|WantedBy\)=.*\(network-online\|multi-user\)\.target/d' \
  -e 's/^ProtectHome=yes/ProtectHome=read-only/'
runtime_units="$XDG_RUNTIME_DIR/systemd/user"
mkdir -p "$runtime_units"
linked=()
target="beaconloc@$robot.target"
services=("${participants[@]/#/beaconloc-}")
services=("${services[@]/%/@$robot.service}")
shm_before="$work/shm_before"
ls /dev/shm >"$shm_before"
killed_files=()

cleanup() {
  systemctl --user stop "$target" "${services[@]}" >/dev/null 2>&1
  systemctl --user reset-failed "$target" "${services[@]}" >/dev/null 2>&1
  for l in "${linked[@]}"; do rm -f "$l"; done
  systemctl --user daemon-reload >/dev/null 2>&1
  # The SIGKILLed participant could not remove its segments: this run's own leftovers.
  for f in "${killed_files[@]}"; do
    if [ -e "/dev/shm/$f" ] && ! grep -qx "$f" "$shm_before"; then rm -f "/dev/shm/$f"; fi
  done
}
trap cleanup EXIT

for f in "$work"/units/*; do
  link="$runtime_units/$(basename "$f")"
  [ -e "$link" ] && fail "$link exists already: not replacing another install's unit"
  ln -s "$f" "$link" && linked+=("$link")
done
systemctl --user daemon-reload || fail "systemctl --user daemon-reload"

prop() { systemctl --user show -P "$2" "$1"; }
shm_files_of() { grep -o '/dev/shm/[^ ]*' "/proc/$1/maps" 2>/dev/null | sed 's|/dev/shm/||' | sort -u; }
status_of_all() { systemctl --user status --no-pager --lines=20 "$target" "${services[@]}"; }
wait_until() {  # wait_until SECONDS COMMAND...: true once COMMAND is
  local end=$((SECONDS + $1))
  shift
  until "$@"; do
    [ $SECONDS -ge $end ] && return 1
    sleep 0.2
  done
}
all_active() {
  for s in "${services[@]}"; do
    [ "$(prop "$s" ActiveState)" = active ] && [ "$(prop "$s" MainPID)" != 0 ] || return 1
  done
}

echo "(b) user manager: starting $target (domain $domain)"
systemctl --user start "$target" || { status_of_all; fail "systemctl --user start $target"; }
wait_until 10 all_active || { status_of_all; fail "the four participants are not all active 10 s after the start"; }
for s in "${services[@]}"; do
  pid=$(prop "$s" MainPID)
  p=${s#beaconloc-}
  p=${p%@*}
  tr '\0' ' ' <"/proc/$pid/cmdline" | grep -q "^$binary $p --config $etc/$robot.yaml" ||
    fail "$s's main process $pid is not '$binary $p --config ...': $(tr '\0' ' ' <"/proc/$pid/cmdline")"
done
echo "(b) started: every participant active, running the build's binary"

# The four hardened units exchange data through /dev/shm: a monitor (this user, the same
# configuration) hears the robot's poses.
monitor_out=$("$binary" monitor --config "$etc/$robot.yaml" --duration-s 8 2>&1)
echo "$monitor_out" | tail -n 5
echo "$monitor_out" | grep -Eq "^monitor: [1-9][0-9]* poses of 1 robot" ||
  { status_of_all; fail "the monitor heard no pose of the robot in 8 s"; }

# kill -9 the gateway: systemd starts it again after RestartSec.
gateway="beaconloc-gateway@$robot.service"
old_pid=$(prop "$gateway" MainPID)
restarts=$(prop "$gateway" NRestarts)
mapfile -t killed_files < <(shm_files_of "$old_pid")
kill -9 "$old_pid"
restarted() {
  local pid
  pid=$(prop "$gateway" MainPID)
  [ "$pid" != 0 ] && [ "$pid" != "$old_pid" ] && [ "$(prop "$gateway" ActiveState)" = active ]
}
t0=$SECONDS
wait_until $((restart_sec + 8)) restarted ||
  { status_of_all; fail "$gateway not restarted within RestartSec + 8 s of its SIGKILL"; }
echo "(b) restarted: $gateway SIGKILLed (pid $old_pid), new main pid $(prop "$gateway" MainPID)" \
  "after <= $((SECONDS - t0 + 1)) s, NRestarts $restarts -> $(prop "$gateway" NRestarts)"

# Stop: every unit inactive after a clean exit, no /dev/shm file of theirs left.
own_files=()
for s in "${services[@]}"; do
  mapfile -t -O "${#own_files[@]}" own_files < <(shm_files_of "$(prop "$s" MainPID)")
done
systemctl --user stop "$target" || fail "systemctl --user stop $target"
for s in "${services[@]}"; do
  state=$(prop "$s" ActiveState) result=$(prop "$s" Result)
  code=$(prop "$s" ExecMainCode) status=$(prop "$s" ExecMainStatus)
  # ExecMainCode 1 is CLD_EXITED: the process exited (not killed), with ExecMainStatus.
  [ "$state" = inactive ] && [ "$result" = success ] && [ "$code" = 1 ] && [ "$status" = 0 ] ||
    { status_of_all; fail "$s after the stop: $state, result $result, exit code $code status $status"; }
done
left=()
for f in $(printf '%s\n' "${own_files[@]}" | sort -u); do
  printf '%s\n' "${killed_files[@]}" | grep -qx "$f" && continue  # the SIGKILLed one's
  [ -e "/dev/shm/$f" ] && left+=("$f")
done
[ ${#left[@]} -eq 0 ] || fail "left in /dev/shm after the stop: ${left[*]}"
own_count=$(printf '%s\n' "${own_files[@]}" | sort -u | wc -l)
echo "(b) stopped: every unit inactive, exit status 0; none of their $own_count /dev/shm files left" \
  "(the SIGKILLed gateway's are removed by this test)"
if [ $verify_ran -eq 1 ]; then
  echo "passed: (a) verify and (b) start/restart/stop"
else
  echo "passed: (b) start/restart/stop; (a) SKIPPED: $verify_reason"
fi
