# Sourced by the shell tests: lease_domain sets `domain` to a DDS domain id no other test run holds,
# by the lock files tests/support/domain_id.cpp leases (/tmp/beaconloc-domain-<id>.lock, 1..200),
# held until the shell exits. Returns 1 when every id is taken.
lease_domain() {
  domain=""
  local k id
  for k in $(seq 0 199); do
    id=$(( 1 + ($$ + k) % 200 ))
    exec {lock_fd}>"/tmp/beaconloc-domain-$id.lock" || continue
    if flock -n "$lock_fd"; then domain=$id; return 0; fi
    exec {lock_fd}>&-
  done
  return 1
}
