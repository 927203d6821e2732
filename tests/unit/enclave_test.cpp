// An enclave's files checked before Fast DDS sees them (dds/security.hpp): each fault a deployment
// meets (no keystore, no enclave, a file missing, an identity expired, not yet valid, revoked,
// issued by another CA, a key that is not the certificate's) is told by name. Keys made by
// scripts/deployment-keys.sh; no participant is created.
#include <gtest/gtest.h>
#include <stdlib.h>

#include <ctime>
#include <filesystem>
#include <string>

#include "beaconloc/dds/security.hpp"
#include "keystore.hpp"

namespace beaconloc {
namespace {

namespace fs = std::filesystem;
using dds::SecurityError;
using testing::deployment_keys;

class EnclaveTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    char dir[] = "/tmp/beaconloc-enclave-XXXXXX";
    ASSERT_NE(::mkdtemp(dir), nullptr);
    dir_ = dir;
    keystore_ = testing::make_deployment(dir_ + "/ks", "robot1");
  }
  static void TearDownTestSuite() { fs::remove_all(dir_); }
  static std::int64_t now() { return static_cast<std::int64_t>(std::time(nullptr)); }
  // The message check_enclave throws, or "" when it accepts the enclave.
  static std::string refusal(const std::string& keystore, const std::string& enclave) {
    try {
      dds::check_enclave({keystore, enclave}, enclave, now());
      return "";
    } catch (const SecurityError& e) {
      return e.what();
    }
  }
  static std::string dir_, keystore_;
};
std::string EnclaveTest::dir_, EnclaveTest::keystore_;

TEST_F(EnclaveTest, EveryRoleOfADeploymentIsAccepted) {
  for (const char* enclave :
       {"/beaconloc/gateway/robot1", "/beaconloc/bridge/robot1", "/beaconloc/decoder", "/beaconloc/localizer",
        "/beaconloc/monitor", "/beaconloc_viewer", "/beaconloc_robot"}) {
    EXPECT_EQ(refusal(keystore_, enclave), "") << enclave;
  }
  const dds::EnclaveFiles files = dds::check_enclave({keystore_, ""}, "/beaconloc/decoder", now());
  EXPECT_EQ(files.certificate, keystore_ + "/enclaves/beaconloc/decoder/cert.pem");
  EXPECT_EQ(files.crl, keystore_ + "/enclaves/beaconloc/decoder/crl.pem");  // where rmw looks for it
}

TEST_F(EnclaveTest, ParticipantsTakeTheirRolesEnclave) {
  EXPECT_EQ(dds::default_enclave("beaconloc.gateway.robot7"), "/beaconloc/gateway/robot7");
  EXPECT_EQ(dds::default_enclave("beaconloc.bridge.robot7"), "/beaconloc/bridge/robot7");
  EXPECT_EQ(dds::default_enclave("beaconloc.decoder"), "/beaconloc/decoder");
  EXPECT_EQ(dds::default_enclave("beaconloc.localizer.range_ekf"), "/beaconloc/localizer");
  EXPECT_EQ(dds::default_enclave("beaconloc.localizer.duhl.shard.host.42"), "/beaconloc/localizer");
  EXPECT_EQ(dds::default_enclave("beaconloc.pose_recorder"), "/beaconloc/monitor");  // read only
  EXPECT_EQ(dds::default_enclave("anything.else"), "/beaconloc/monitor");
}

TEST_F(EnclaveTest, NoKeystoreNoEnclaveOrAMissingFileIsNamed) {
  EXPECT_NE(refusal(dir_ + "/nowhere", "/beaconloc/decoder").find("is not a directory"), std::string::npos);
  EXPECT_NE(refusal(keystore_, "/beaconloc/gateway/robot9").find("has no enclave /beaconloc/gateway/robot9"),
            std::string::npos);
  EXPECT_NE(refusal(keystore_, "beaconloc/decoder").find("not an absolute name"), std::string::npos);
  EXPECT_NE(refusal(keystore_, "/beaconloc/../private").find("not an absolute name"), std::string::npos);
  // A copy of an enclave without its permissions.
  const fs::path copy = fs::path(keystore_) / "enclaves/beaconloc/copy";
  fs::copy(fs::path(keystore_) / "enclaves/beaconloc/decoder", copy);
  fs::remove(copy / "permissions.p7s");
  EXPECT_NE(refusal(keystore_, "/beaconloc/copy").find("permissions.p7s is missing"), std::string::npos);
  fs::remove_all(copy);
}

TEST_F(EnclaveTest, ExpiredAndNotYetValidIdentitiesAreRefused) {
  deployment_keys("enclave " + keystore_ + " decoder --enclave /expired --not-before 20200101000000Z " +
                  "--not-after 20200201000000Z");
  EXPECT_NE(refusal(keystore_, "/expired").find("expired on Feb  1 00:00:00 2020 GMT"), std::string::npos)
      << refusal(keystore_, "/expired");
  deployment_keys("enclave " + keystore_ + " decoder --enclave /future --not-before 20300101000000Z " +
                  "--not-after 20300201000000Z");  // within the CA's ten years
  EXPECT_NE(refusal(keystore_, "/future").find("is not valid before"), std::string::npos);
}

TEST_F(EnclaveTest, AForeignIdentityAndAKeyThatIsNotTheCertificatesAreRefused) {
  // An identity of another deployment, its CA not ours.
  const std::string other = testing::make_deployment(dir_ + "/other", "robot1");
  const fs::path foreign = fs::path(keystore_) / "enclaves/foreign";
  fs::copy(fs::path(keystore_) / "enclaves/beaconloc/decoder", foreign);
  fs::copy_file(fs::path(other) / "enclaves/beaconloc/decoder/cert.pem", foreign / "cert.pem",
                fs::copy_options::overwrite_existing);
  fs::copy_file(fs::path(other) / "enclaves/beaconloc/decoder/key.pem", foreign / "key.pem",
                fs::copy_options::overwrite_existing);
  EXPECT_NE(refusal(keystore_, "/foreign").find("is not accepted by the identity CA"), std::string::npos)
      << refusal(keystore_, "/foreign");
  // Our certificate with another enclave's key.
  const fs::path swapped = fs::path(keystore_) / "enclaves/swapped";
  fs::copy(fs::path(keystore_) / "enclaves/beaconloc/decoder", swapped);
  fs::copy_file(fs::path(keystore_) / "enclaves/beaconloc/localizer/key.pem", swapped / "key.pem",
                fs::copy_options::overwrite_existing);
  EXPECT_NE(refusal(keystore_, "/swapped").find("is not the key of"), std::string::npos)
      << refusal(keystore_, "/swapped");
}

TEST_F(EnclaveTest, PermissionsNotSignedByTheCaOrNotForThisIdentityOrExpiredAreRefused) {
  const std::string other = testing::make_deployment(dir_ + "/other_ca", "robot1");
  const fs::path foreign = fs::path(keystore_) / "enclaves/foreign_permissions";
  fs::copy(fs::path(keystore_) / "enclaves/beaconloc/decoder", foreign);
  fs::copy_file(fs::path(other) / "enclaves/beaconloc/decoder/permissions.p7s", foreign / "permissions.p7s",
                fs::copy_options::overwrite_existing);
  EXPECT_NE(refusal(keystore_, "/foreign_permissions").find("is not signed by the permissions CA"),
            std::string::npos)
      << refusal(keystore_, "/foreign_permissions");
  // The localizer's permissions beside the decoder's identity.
  const fs::path borrowed = fs::path(keystore_) / "enclaves/borrowed";
  fs::copy(fs::path(keystore_) / "enclaves/beaconloc/decoder", borrowed);
  fs::copy_file(fs::path(keystore_) / "enclaves/beaconloc/localizer/permissions.p7s",
                borrowed / "permissions.p7s", fs::copy_options::overwrite_existing);
  EXPECT_NE(
      refusal(keystore_, "/borrowed")
          .find("grant nothing to this identity (CN=/beaconloc/decoder); they name CN=/beaconloc/localizer"),
      std::string::npos)
      << refusal(keystore_, "/borrowed");
  // A grant that expired, beside a valid identity of the same name.
  deployment_keys("enclave " + keystore_ + " decoder --enclave /lapsed --not-before 20200101000000Z " +
                  "--not-after 20200201000000Z");
  const fs::path lapsed = fs::path(keystore_) / "enclaves/lapsed";
  const std::string expired_grant = dir_ + "/lapsed_permissions.p7s";
  fs::copy_file(lapsed / "permissions.p7s", expired_grant);
  deployment_keys("enclave " + keystore_ + " decoder --enclave /lapsed");
  fs::copy_file(expired_grant, lapsed / "permissions.p7s", fs::copy_options::overwrite_existing);
  EXPECT_NE(refusal(keystore_, "/lapsed").find("the grant of CN=/lapsed expired on 2020-02-01T00:00:00"),
            std::string::npos)
      << refusal(keystore_, "/lapsed");
}

TEST_F(EnclaveTest, NoIdentityOutlivesTheCa) {
  EXPECT_THROW(deployment_keys("enclave " + keystore_ + " decoder --enclave /forever --days 99999"),
               std::runtime_error);
  EXPECT_FALSE(fs::exists(fs::path(keystore_) / "enclaves/forever/cert.pem"));
}

TEST_F(EnclaveTest, ARevokedIdentityIsRefusedOnceTheListIsReissued) {
  deployment_keys("enclave " + keystore_ + " monitor --enclave /to_revoke");
  EXPECT_EQ(refusal(keystore_, "/to_revoke"), "");
  deployment_keys("revoke " + keystore_ + " /to_revoke");
  EXPECT_NE(refusal(keystore_, "/to_revoke").find("certificate revoked"), std::string::npos)
      << refusal(keystore_, "/to_revoke");
  EXPECT_EQ(refusal(keystore_, "/beaconloc/monitor"), "");  // the others stand
}

TEST_F(EnclaveTest, IssuingAnEnclaveAgainRevokesTheIdentityItHad) {
  deployment_keys("enclave " + keystore_ + " decoder --enclave /rotated");
  const fs::path before = fs::path(keystore_) / "enclaves/rotated_before";
  fs::copy(fs::path(keystore_) / "enclaves/rotated", before);  // what a thief of the old key holds
  EXPECT_EQ(refusal(keystore_, "/rotated_before"), "");
  deployment_keys("enclave " + keystore_ + " decoder --enclave /rotated");
  EXPECT_EQ(refusal(keystore_, "/rotated"), "");
  EXPECT_NE(refusal(keystore_, "/rotated_before").find("certificate revoked"), std::string::npos)
      << refusal(keystore_, "/rotated_before");
}

}  // namespace
}  // namespace beaconloc
