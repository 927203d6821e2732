#!/usr/bin/env bash
# A deployment's DDS Security keys, made with Debian's openssl, in the layout of an SROS2 keystore
# (ROS 2's `ros2 security`), so that a ROS 2 node with SROS2 security joins the same deployment:
#
#   KEYSTORE/public/ca.cert.pem             the one CA: identities and permissions (as SROS2's default)
#   KEYSTORE/public/identity_ca.cert.pem, permissions_ca.cert.pem   -> ca.cert.pem
#   KEYSTORE/public/crl.pem                 revoked identities (every participant loads it; a copy,
#                                           crl.pem, in every enclave, where rmw looks for it)
#   KEYSTORE/private/ca.key.pem             the CA's key: keep it off the robots
#   KEYSTORE/enclaves/governance.xml, governance.p7s   discovery, liveliness and data encrypted,
#                                           no unauthenticated participant, access control on every topic
#   KEYSTORE/enclaves/<enclave>/            one per participant: cert.pem, key.pem, identity_ca.cert.pem,
#                                           permissions_ca.cert.pem, governance.p7s, permissions.xml,
#                                           permissions.p7s, crl.pem (what rmw and `beaconloc --keystore` read)
#
# Usage:
#   deployment-keys.sh deployment KEYSTORE ROBOT[,ROBOT...] [--days N] [--ca-days N]
#       the CA, the governance and every role's enclave: gateway and bridge per robot, decoder,
#       localizer, monitor, and two for ROS 2 nodes beside the bridge: /beaconloc_viewer (reads its
#       outputs, as rviz2) and /beaconloc_robot (a robot's drivers: /odom, /scan, /initialpose in)
#   deployment-keys.sh init KEYSTORE [--ca-days N]
#   deployment-keys.sh enclave KEYSTORE ROLE [ROBOT] [--enclave NAME] [--days N] [--not-before T --not-after T]
#       ROLE: gateway ROBOT | bridge ROBOT | decoder | localizer | monitor | ros2-viewer | ros2-robot
#             | bench (benchmarks/latency's stand-in gateway of any robot: never in a deployment)
#       T: YYYYMMDDHHMMSSZ (UTC); --not-after in the past makes an expired identity (for tests).
#       Issuing an enclave that exists replaces its key and permissions and revokes the identity it had.
#   deployment-keys.sh revoke KEYSTORE ENCLAVE
#       revokes the enclave's identity certificate: re-issues the CRL every participant checks
#
# --days: an identity's and its permissions' validity (365); --ca-days: the CA's (3650). An identity
# may not outlive the CA. The CA and the CRL are dated a day back and an identity a minute back, so
# that a robot whose clock is behind the issuing machine's takes them. Fast DDS 2.9 reads a
# permissions grant's times as local time: the grant starts a day back, and on a host whose zone is
# not UTC it ends up to that zone's offset off the identity's end.
#
# Enclaves are what `beaconloc ... --keystore KEYSTORE` picks by default: /beaconloc/gateway/ROBOT,
# /beaconloc/bridge/ROBOT, /beaconloc/decoder, /beaconloc/localizer (every shard), and
# /beaconloc/monitor for any other participant (monitor, recorders): read only.
# A robot id is [A-Za-z0-9_-]+: it becomes a partition in a permission, where '*' or '?' would be a
# pattern granting more robots.
set -euo pipefail

die() {
  echo "deployment-keys.sh: $*" >&2
  exit 2
}
# openssl ARGS...: quiet, and its own words when it fails.
ossl() {
  local out
  out=$(openssl "$@" 2>&1) || die "openssl $1 failed: $out"
}

# The topics of the beaconloc bus (plugins/sdk/dds/include/beaconloc/dds/topics.hpp) and the bridge's
# ROS 2 topics (bridge/bridge_participant.cpp). A robot's own topics (TopicSpec::per_robot) travel
# in the partition robot/ROBOT: its measurements, and the initial pose its bridge takes from /initialpose.
readonly ROBOT_MEASUREMENTS="beaconloc/raw_tof beaconloc/pulse_arrival beaconloc/odometry beaconloc/laser_scan"
readonly ROBOT_TOPICS="$ROBOT_MEASUREMENTS beaconloc/initial_pose"
# The bridge's ROS 2 topics, with and without its --namespace (tf and tf_static are never namespaced).
readonly ROS2_OUT="rt/beacon_pose rt/*/beacon_pose rt/odometry/beacons rt/*/odometry/beacons rt/tf rt/tf_static
  rt/beacons rt/*/beacons rt/beacon_ranges rt/*/beacon_ranges"
readonly ROS2_IN="rt/odom rt/*/odom rt/scan rt/*/scan rt/initialpose rt/*/initialpose"
# What any rclcpp node publishes and reads besides its own topics (rmw's discovery, rosout,
# parameter events, parameter services).
readonly ROS2_NODE_OUT="ros_discovery_info rt/rosout rt/parameter_events rr/*"
readonly ROS2_NODE_IN="ros_discovery_info rt/parameter_events rq/*"
# The highest domain id the governance and grants cover (dds::kMaxSecuredDomainId): Cyclone DDS
# 0.10, a ROS 2 peer, refuses a governance naming one above 230.
readonly MAX_DOMAIN=230

days=365
ca_days=3650
not_before=""
not_after=""

utc() { date -u -d "$1" +%Y%m%d%H%M%SZ; }
# YYYYMMDDHHMMSSZ -> seconds since the epoch.
epoch() { local t=$1; date -u -d "${t:0:4}-${t:4:2}-${t:6:2} ${t:8:2}:${t:10:2}:${t:12:2}" +%s; }
# YYYYMMDDHHMMSSZ -> the xs:dateTime of a permissions grant.
xml_time() { local t=$1; echo "${t:0:4}-${t:4:2}-${t:6:2}T${t:8:2}:${t:10:2}:${t:12:2}"; }

ca_config() {
  local ks=$1
  cat > "$ks/private/ca.cnf" <<EOF
[ ca ]
default_ca = beaconloc_ca
[ beaconloc_ca ]
dir = $ks/private
database = \$dir/index.txt
serial = \$dir/serial
crlnumber = \$dir/crlnumber
new_certs_dir = \$dir/issued
certificate = $ks/public/ca.cert.pem
private_key = \$dir/ca.key.pem
default_md = sha256
default_crl_days = 3650
policy = anything
unique_subject = no
copy_extensions = none
[ anything ]
commonName = supplied
[ ca_extensions ]
basicConstraints = critical,CA:true
subjectKeyIdentifier = hash
EOF
}

# The CRL, re-issued (dated a day back), and its copy in every enclave.
refresh_crl() {
  local ks=$1 dir
  ossl ca -batch -config "$ks/private/ca.cnf" -gencrl -crl_lastupdate "$(utc "now - 1 day")" \
    -out "$ks/public/crl.pem"
  while IFS= read -r dir; do cp "$ks/public/crl.pem" "$dir/crl.pem"; done < <(
    find "$ks/enclaves" -name cert.pem -printf '%h\n')
}

sign_smime() {  # sign_smime KEYSTORE IN OUT: an S/MIME document signed by the CA (DDS Security 9.4.1.2)
  ossl smime -sign -text -in "$2" -out "$3" -signer "$1/public/ca.cert.pem" -inkey "$1/private/ca.key.pem"
}

init() {
  local ks=$1
  [ -e "$ks/private/ca.key.pem" ] && die "$ks already has a CA (remove it to start again)"
  mkdir -p "$ks/public" "$ks/private/issued" "$ks/enclaves"
  chmod 700 "$ks/private"
  : > "$ks/private/index.txt"
  echo 1000 > "$ks/private/serial"
  echo 1000 > "$ks/private/crlnumber"
  ca_config "$ks"
  ossl ecparam -name prime256v1 -genkey -noout -out "$ks/private/ca.key.pem"
  chmod 600 "$ks/private/ca.key.pem"
  ossl req -new -key "$ks/private/ca.key.pem" -subj "/CN=beaconloc deployment CA" -out "$ks/private/ca.csr"
  ossl ca -batch -selfsign -config "$ks/private/ca.cnf" -keyfile "$ks/private/ca.key.pem" -in "$ks/private/ca.csr" \
    -out "$ks/public/ca.cert.pem" -notext -extensions ca_extensions \
    -startdate "$(utc "now - 1 day")" -enddate "$(utc "now + $ca_days days")"
  rm -f "$ks/private/ca.csr"
  ln -sf ca.cert.pem "$ks/public/identity_ca.cert.pem"
  ln -sf ca.cert.pem "$ks/public/permissions_ca.cert.pem"
  ln -sf ca.key.pem "$ks/private/identity_ca.key.pem"
  ln -sf ca.key.pem "$ks/private/permissions_ca.key.pem"
  refresh_crl "$ks"
  # Domains 0..MAX_DOMAIN, no unauthenticated participant, discovery, liveliness and every topic's
  # data encrypted, read and write access control on every topic (a participant reads and writes
  # only what its signed permissions grant). The protection kinds are SROS2's defaults, so a ROS 2
  # node with SROS2 security joins (tests/interop/cyclone_ros2_peer.cpp does, as Cyclone DDS).
  cat > "$ks/enclaves/governance.xml" <<EOF
<?xml version="1.0" encoding="UTF-8"?>
<dds xmlns:xsi="http://www.w3.org/2001/XMLSchema-instance"
     xsi:noNamespaceSchemaLocation="http://www.omg.org/spec/DDS-SECURITY/20170901/omg_shared_ca_governance.xsd">
  <domain_access_rules>
    <domain_rule>
      <domains><id_range><min>0</min><max>$MAX_DOMAIN</max></id_range></domains>
      <allow_unauthenticated_participants>false</allow_unauthenticated_participants>
      <enable_join_access_control>true</enable_join_access_control>
      <discovery_protection_kind>ENCRYPT</discovery_protection_kind>
      <liveliness_protection_kind>ENCRYPT</liveliness_protection_kind>
      <rtps_protection_kind>SIGN</rtps_protection_kind>
      <topic_access_rules>
        <topic_rule>
          <topic_expression>*</topic_expression>
          <enable_discovery_protection>true</enable_discovery_protection>
          <enable_liveliness_protection>true</enable_liveliness_protection>
          <enable_read_access_control>true</enable_read_access_control>
          <enable_write_access_control>true</enable_write_access_control>
          <metadata_protection_kind>ENCRYPT</metadata_protection_kind>
          <data_protection_kind>ENCRYPT</data_protection_kind>
        </topic_rule>
      </topic_access_rules>
    </domain_rule>
  </domain_access_rules>
</dds>
EOF
  sign_smime "$ks" "$ks/enclaves/governance.xml" "$ks/enclaves/governance.p7s"
}

topics_xml() { local t; for t in "$@"; do printf '<topic>%s</topic>' "$t"; done; }
# rule KIND PARTITION TOPIC...: an allow rule of one publish or subscribe criterion (an empty
# PARTITION: the default one). One criterion per rule: Fast DDS 2.9 checks a writer's or reader's
# partitions against every criterion of the first rule naming its topic, so criteria of different
# partitions in one rule would let each topic use the other's partitions.
rule() {
  local kind=$1 partition=$2
  shift 2
  printf '      <allow_rule>\n        <domains><id_range><min>0</min><max>%s</max></id_range></domains>\n' \
    "$MAX_DOMAIN"
  printf '        <%s><topics>%s</topics>' "$kind" "$(topics_xml "$@")"
  if [ -n "$partition" ]; then printf '<partitions><partition>%s</partition></partitions>' "$partition"; fi
  printf '</%s>\n      </allow_rule>\n' "$kind"
}

# grants ROLE ROBOT: what a role may publish and read (the participants' code: plugins/*/, bridge/).
grants() {
  local role=$1 robot=$2
  # shellcheck disable=SC2086  # the topic lists are meant to split
  case "$role" in
    gateway)  # its own robot's measurements only; the site's map; fires by the plans for it
      rule publish "robot/$robot" $ROBOT_MEASUREMENTS
      rule publish "" beaconloc/beacon_map beaconloc/diagnostics
      rule subscribe "" beaconloc/firing_plan ;;
    decoder)
      rule subscribe "robot/*" beaconloc/raw_tof
      rule subscribe "" beaconloc/beacon_map
      rule publish "" beaconloc/beacon_range beaconloc/diagnostics ;;
    localizer)  # any robot's measurements and initial pose; poses, plans, calibrations, shards
      rule subscribe "robot/*" $ROBOT_TOPICS
      rule subscribe "" beaconloc/beacon_range beaconloc/beacon_map beaconloc/beacon_calibration \
        beaconloc/diagnostics beaconloc/localizer_shard
      rule publish "" beaconloc/pose_estimate beaconloc/estimator_state beaconloc/firing_plan \
        beaconloc/beacon_calibration beaconloc/diagnostics beaconloc/localizer_shard ;;
    bridge)  # ROS 2 out; its robot's /odom, /scan and /initialpose in
      rule subscribe "robot/*" beaconloc/odometry
      rule subscribe "" beaconloc/pose_estimate beaconloc/beacon_map beaconloc/beacon_range
      rule publish "robot/$robot" beaconloc/odometry beaconloc/laser_scan beaconloc/initial_pose
      rule publish "" beaconloc/diagnostics $ROS2_OUT
      rule subscribe "" $ROS2_IN ;;
    monitor)  # reads, never writes
      rule subscribe "robot/*" $ROBOT_TOPICS
      rule subscribe "" 'beaconloc/*' ;;
    ros2-viewer)  # a ROS 2 node reading what the bridge publishes, as rviz2
      rule subscribe "" $ROS2_OUT $ROS2_NODE_IN
      rule publish "" $ROS2_NODE_OUT ;;
    ros2-robot)  # a robot's ROS 2 drivers: /odom, /scan and /initialpose to the bridge; its outputs back
      rule publish "" $ROS2_IN $ROS2_NODE_OUT
      rule subscribe "" $ROS2_OUT $ROS2_NODE_IN ;;
    bench)  # benchmarks/latency: a stand-in gateway of any robot that reads the poses; its ping-pong
      rule publish "robot/*" $ROBOT_MEASUREMENTS
      rule publish "" beaconloc/beacon_map 'beaconloc_latency/*'
      rule subscribe "" beaconloc/pose_estimate 'beaconloc_latency/*' ;;
    *) die "unknown role '$role' (gateway, bridge, decoder, localizer, monitor, ros2-viewer, ros2-robot, bench)" ;;
  esac
}

default_enclave() {
  case "$1" in
    gateway | bridge) echo "/beaconloc/$1/$2" ;;
    ros2-viewer) echo "/beaconloc_viewer" ;;
    ros2-robot) echo "/beaconloc_robot" ;;
    *) echo "/beaconloc/$1" ;;
  esac
}

check_robot() { [[ "$1" =~ ^[A-Za-z0-9_-]+$ ]] || die "a robot id is [A-Za-z0-9_-]+, got '$1'"; }

# Revokes the certificate unless the CRL already holds it.
revoke_certificate() {
  local ks=$1 cert=$2 serial
  serial=$(openssl x509 -in "$cert" -noout -serial) || die "cannot read $cert"
  serial=${serial#serial=}
  if ! awk -F'\t' -v s="$serial" '$1 == "R" && $4 == s { found = 1 } END { exit !found }' "$ks/private/index.txt"; then
    ossl ca -batch -config "$ks/private/ca.cnf" -revoke "$cert"
  fi
}

enclave() {
  local ks=$1 role=$2 robot=${3:-} name=${4:-}
  [ -f "$ks/private/ca.key.pem" ] || die "$ks has no CA: run 'deployment-keys.sh init $ks' first"
  case "$role" in
    gateway | bridge) check_robot "$robot" ;;
    *) [ -z "$robot" ] || die "role $role takes no robot" ;;
  esac
  if [ "$role" = bench ]; then
    echo "deployment-keys.sh: warning: role bench may publish any robot's measurements (benchmarks only)" >&2
  fi
  [ -n "$name" ] || name=$(default_enclave "$role" "$robot")
  [[ "$name" =~ ^(/[A-Za-z0-9_-]+)+$ ]] || die "enclave '$name' is not a path of [A-Za-z0-9_-] names"
  local dir="$ks/enclaves$name" start=${not_before:-$(utc "now - 1 minute")}
  local end=${not_after:-$(utc "now + $days days")} ca_end
  ca_end=$(utc "$(openssl x509 -in "$ks/public/ca.cert.pem" -noout -enddate | cut -d= -f2)")
  [ "$(epoch "$end")" -le "$(epoch "$ca_end")" ] || die "$name would outlive the CA (it ends $ca_end): fewer --days"
  # Made aside, then put in place: a failure leaves the enclave as it was.
  local new="$dir.new"
  rm -rf "$new"
  mkdir -p "$new"
  (
    umask 077
    ossl ecparam -name prime256v1 -genkey -noout -out "$new/key.pem"
  )
  # The identity's subject is the enclave's name, as SROS2 writes it (CN=/ns/node).
  ossl req -new -key "$new/key.pem" -subj "/CN=${name//\//\\/}" -out "$new/req.csr"
  ossl ca -batch -config "$ks/private/ca.cnf" -in "$new/req.csr" -out "$new/cert.pem" -notext \
    -startdate "$start" -enddate "$end"
  rm -f "$new/req.csr"
  cp "$ks/public/ca.cert.pem" "$new/identity_ca.cert.pem"
  cp "$ks/public/ca.cert.pem" "$new/permissions_ca.cert.pem"
  cp "$ks/enclaves/governance.p7s" "$new/governance.p7s"
  {
    echo '<?xml version="1.0" encoding="UTF-8"?>'
    echo '<dds xmlns:xsi="http://www.w3.org/2001/XMLSchema-instance"'
    echo -n '     xsi:noNamespaceSchemaLocation='
    echo '"http://www.omg.org/spec/DDS-SECURITY/20170901/omg_shared_ca_permissions.xsd">'
    echo '  <permissions>'
    echo "    <grant name=\"$name\">"
    echo "      <subject_name>CN=$name</subject_name>"
    echo "      <validity><not_before>$(xml_time "$(utc "$(date -u -d @"$(epoch "$start")") - 1 day")")</not_before>"
    echo "        <not_after>$(xml_time "$end")</not_after></validity>"
    grants "$role" "$robot"
    echo '      <default>DENY</default>'
    echo '    </grant>'
    echo '  </permissions>'
    echo '</dds>'
  } > "$new/permissions.xml"
  sign_smime "$ks" "$new/permissions.xml" "$new/permissions.p7s"
  # Issued again: the identity it had is revoked (a key rotated away may be a key lost).
  if [ -f "$dir/cert.pem" ]; then revoke_certificate "$ks" "$dir/cert.pem"; fi
  mkdir -p "$dir"
  mv -f "$new"/* "$dir"/
  rmdir "$new"
  refresh_crl "$ks"
  echo "$name"
}

revoke() {
  local ks=$1 name=$2 cert="$1/enclaves$2/cert.pem"
  [ -f "$cert" ] || die "no enclave $name in $ks"
  revoke_certificate "$ks" "$cert"
  refresh_crl "$ks"
  echo "revoked $name: re-issued $ks/public/crl.pem and every enclave's crl.pem"
}

command=${1:-}
[ $# -ge 2 ] || die "usage: deployment-keys.sh deployment|init|enclave|revoke KEYSTORE ... (see the script's head)"
shift
keystore=$(realpath -m "$1")
shift
args=()
enclave_name=""
while [ $# -gt 0 ]; do
  case "$1" in
    --days) days=${2:?}; shift 2 ;;
    --ca-days) ca_days=${2:?}; shift 2 ;;
    --not-before) not_before=${2:?}; shift 2 ;;
    --not-after) not_after=${2:?}; shift 2 ;;
    --enclave) enclave_name=${2:?}; shift 2 ;;
    *) args+=("$1"); shift ;;
  esac
done
for n in "$days" "$ca_days"; do [[ "$n" =~ ^[1-9][0-9]{0,4}$ ]] || die "--days and --ca-days take 1..99999"; done
for t in "$not_before" "$not_after"; do
  [ -z "$t" ] || [[ "$t" =~ ^[0-9]{14}Z$ ]] || die "a time is YYYYMMDDHHMMSSZ, got '$t'"
done
case "$command" in
  init) init "$keystore" ;;
  enclave) enclave "$keystore" "${args[0]:?a role}" "${args[1]:-}" "$enclave_name" ;;
  revoke) revoke "$keystore" "${args[0]:?an enclave}" ;;
  deployment)
    IFS=, read -r -a robots <<< "${args[0]:?robot ids, comma separated}"
    for robot in "${robots[@]}"; do check_robot "$robot"; done  # before anything is written
    init "$keystore"
    for role in decoder localizer monitor ros2-viewer ros2-robot; do enclave "$keystore" "$role"; done
    for robot in "${robots[@]}"; do
      enclave "$keystore" gateway "$robot"
      enclave "$keystore" bridge "$robot"
    done ;;
  *) die "unknown command '$command' (deployment, init, enclave, revoke)" ;;
esac
