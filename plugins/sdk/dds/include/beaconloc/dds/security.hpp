#pragma once
// DDS Security for a participant: its identity and permissions from a keystore in SROS2's layout
// (scripts/deployment-keys.sh makes one), checked before Fast DDS sees them so that a missing,
// expired, revoked or foreign certificate is told by name; and the participant properties that
// turn on Fast DDS's builtin plugins (PKI-DH, Access-Permissions, AES-GCM-GMAC).
#include <cstdint>
#include <fastdds/dds/domain/qos/DomainParticipantQos.hpp>
#include <stdexcept>
#include <string>

namespace beaconloc::dds {

// The highest domain id a deployment's governance covers (scripts/deployment-keys.sh: Cyclone DDS
// 0.10, a ROS 2 peer, refuses a governance naming one above 230).
inline constexpr int kMaxSecuredDomainId = 230;

struct SecurityOptions {
  std::string keystore;  // an SROS2 keystore directory; empty: security off
  std::string enclave;   // e.g. /beaconloc/gateway/robot1; empty: default_enclave(participant name)
  bool enabled() const { return !keystore.empty(); }
};

class SecurityError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// The enclave a participant takes when none is given, by its name (the roles of
// scripts/deployment-keys.sh): beaconloc.gateway.R -> /beaconloc/gateway/R, beaconloc.bridge.R ->
// /beaconloc/bridge/R, beaconloc.decoder -> /beaconloc/decoder, beaconloc.localizer.* (every
// estimator and shard) -> /beaconloc/localizer; any other (monitor, recorders) -> /beaconloc/monitor,
// which may only read.
std::string default_enclave(const std::string& participant_name);

// The files of one enclave, absolute paths.
struct EnclaveFiles {
  std::string identity_ca, certificate, private_key, permissions_ca, governance, permissions;
  std::string crl;  // the enclave's crl.pem, else KEYSTORE/public/crl.pem; empty when neither is there
};

// The enclave's files, checked against the time now_unix_s: each is there and readable, the
// identity certificate is within its validity, issued by the enclave's identity CA, not revoked
// (the CRL), and its key is the certificate's; the governance and the permissions are signed by
// the permissions CA, and the permissions' grant names this identity and is valid now. Throws
// SecurityError saying which file and what is wrong (Fast DDS 2.9 refuses these without a word).
EnclaveFiles check_enclave(const SecurityOptions& options, const std::string& enclave,
                           std::int64_t now_unix_s);

// Sets the properties that enable authentication, access control and encryption with these files.
void enable_security(const EnclaveFiles& files, eprosima::fastdds::dds::DomainParticipantQos& qos);

// Messages a secured participant of this process received and could not decode (a tag that does
// not match: tampered, or not from whom it claims), counted from Fast DDS's security log by a log
// consumer installed with the first secured participant in place of Fast DDS's default one (its
// errors are printed as that one printed them, on stdout; its warnings, which the default verbosity
// left out, are dropped). Only tag failures ("Error decoding content") are counted: a message whose
// framing was altered fails elsewhere, as an error printed. Process-wide: Fast DDS does not say
// which participant received them.
std::uint64_t undecodable_secure_messages();

}  // namespace beaconloc::dds
