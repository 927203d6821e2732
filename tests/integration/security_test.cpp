// A secured deployment (DDS Security: scripts/deployment-keys.sh, `--keystore`) under attack: a
// gateway, decoder and localizer as processes with their roles' identities, and attackers in this
// process. Each attack sends what would show if it got through: odometry or times of flight with
// a NaN, which the localizer and decoder count by reason (non_finite_odometry, non_finite_tof).
// Where an attack is stopped, a control from an attacker that may send shows the count moving,
// so that a zero means "stopped", not "never looked at".
#include <beaconlocPubSubTypes.h>
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <filesystem>
#include <memory>
#include <string>

#include "beaconloc/dds/convert.hpp"
#include "diagnostics_recorder.hpp"
#include "keystore.hpp"
#include "participants_test.hpp"
#include "pose_recorder.hpp"
#include "process.hpp"
#include "scoped_env.hpp"
#include "tampering_transport.hpp"

namespace beaconloc::testing {
namespace {

using namespace std::chrono_literals;
namespace fs = std::filesystem;

// How the localizer counts odometry with a NaN (by topic and reason, as its Diagnostics name it).
const std::string kNanOdometry = "odometry.non_finite_odometry";

class Security : public ParticipantsTest {
 protected:
  void SetUp() override {
    ASSERT_NO_FATAL_FAILURE(ParticipantsTest::SetUp());
    keystore_ = make_deployment(path("keystore"), "robot1,robot2");
    secured_ = dds_;
    secured_.security.keystore = keystore_;
  }
  // Options of a participant of this process with the enclave's identity.
  dds::DdsOptions as(const std::string& enclave) const {
    dds::DdsOptions o = secured_;
    o.security.enclave = enclave;
    return o;
  }
  // The secured pipeline: a simulated robot1 until stopped, the decoder and the localizer, each
  // with its role's default enclave; returns once the localizer has localized robot1 for 1 s and,
  // given a test's `diagnostics` reader, once that has heard the decoder and the localizer too (a
  // count the test reads there as 0 must be one they reported, not one never heard).
  // Started again, said on stdout, when a start falls short: Fast DDS 2.9 sometimes leaves a
  // secured pair of participants unable to deliver anything (docs/security.md; a participant that
  // never got the beacon map, a range, pose or Diagnostics pair mute), which is not what these
  // tests are about. A few starts in a hundred here, so up to three starts; a third failure fails.
  void start_pipeline(const PoseRecorder& poses, const DiagnosticsRecorder* diagnostics = nullptr) {
    const std::vector<std::string> keys{"--keystore", keystore_};
    constexpr int kAttempts = 3;
    for (int attempt = 1;; ++attempt) {
      gateway_ = std::make_unique<ChildProcess>(
          command("gateway", {"--keystore", keystore_, "--robot", "robot1", "--duration-s", "0"}),
          path("gateway.log"));
      decoder_ = std::make_unique<ChildProcess>(command("decoder", keys), path("decoder.log"));
      localizer_ = std::make_unique<ChildProcess>(command("localizer", keys), path("localizer.log"));
      const bool localized = wait_for_pose_span(poses, "robot1", 1s);
      const bool heard =
          localized && (!diagnostics || wait_until_reporting(*diagnostics, {kDecoder, kRangeEkfLocalizer}, 10s));
      if (heard) return;
      // What each participant says of itself, through a new reader of this process.
      DiagnosticsRecorder reporter(secured_);
      std::this_thread::sleep_for(3s);
      bool map_lost = false;
      for (const auto& [name, report] : reporter.reports()) {
        print_report(name, report, std::cout);
        map_lost = map_lost || report.last.message().find("waiting for the beacon map") != std::string::npos;
      }
      const char* why = map_lost     ? "a participant never got the beacon map"
                        : !localized ? "no secured pose reached this process"
                                     : "the test's Diagnostics reader never heard the decoder and the localizer";
      if (attempt < kAttempts) {
        // Any pair of the pipeline, or one to this process's readers, may be the mute one.
        std::cout << why << " (Fast DDS 2.9 secured matching): started again\n";
        for (auto* p : {&gateway_, &decoder_, &localizer_}) {
          ASSERT_NO_FATAL_FAILURE(stop_cleanly(**p, "participant"));
          p->reset();
        }
        continue;
      }
      FAIL() << why << " (" << poses.count() << " poses)\n" << gateway_->log() << decoder_->log() << localizer_->log();
    }
  }
  void TearDown() override {
    for (auto* p : {&gateway_, &decoder_, &localizer_}) {
      if (*p) stop_cleanly(**p, "participant");
      p->reset();
    }
    ParticipantsTest::TearDown();
  }
  // NaN odometry of `robot`, `count` samples 10 ms apart, written by `writer`.
  void write_nan_odometry(const dds::Writer& writer, const std::string& robot, int count) {
    for (int i = 0; i < count; ++i) {
      OdometrySample o;
      o.stamp_ns = (1000 + ++sent_) * 10 * kNsPerMillisecond;
      o.wheel_base_m = 0.33;
      o.wheel_velocity_left_mps = std::nan("");
      o.wheel_velocity_covariance = 1e-6 * Eigen::Matrix2d::Identity();
      auto m = dds::to_msg(robot, o, static_cast<std::uint64_t>(sent_));
      writer->write(&m);
      std::this_thread::sleep_for(10ms);
    }
  }
  // The localizer's count of `reason` once it is at least `at_least` (or the newest seen after
  // waiting `timeout` for that), and then again after a further `settle`: what arrives late is
  // counted too.
  static std::uint64_t localizer_count(const DiagnosticsRecorder& d, const std::string& reason,
                                       std::uint64_t at_least, std::chrono::milliseconds settle = 1500ms,
                                       std::chrono::milliseconds timeout = 10s) {
    wait_for_diagnostics(
        d, kRangeEkfLocalizer,
        [&](const msg::Diagnostics& r) { return rejected_count(r, reason) >= at_least; }, timeout);
    std::this_thread::sleep_for(scaled(settle));
    return rejected_count(wait_for_diagnostics(d, kRangeEkfLocalizer, [](const auto&) { return true; }),
                          reason);
  }
  // Writes NaN odometry of `robot` a sample at a time until the localizer counts one: the path from
  // this writer is up. Matched is not enough: a secured reader drops what comes before it holds the
  // writer's keys, and odometry's lifespan outlives no repair. Returns the count it reached (0:
  // never, after 15 s).
  std::uint64_t deliver(const DiagnosticsRecorder& d, const dds::Writer& writer, const std::string& robot) {
    const std::uint64_t before = localizer_count(d, kNanOdometry, 0, 0ms);
    std::uint64_t now = before;
    eventually(
        [&] {
          write_nan_odometry(writer, robot, 1);
          now = localizer_count(d, kNanOdometry, before + 1, 0ms, 200ms);
          return now > before;
        },
        15s);
    if (now == before) return 0;
    return localizer_count(d, kNanOdometry, 0);  // once the samples written in the meantime are counted too
  }
  // A participant of this process with `options` and its odometry writer in `robot`'s partition,
  // once what it writes reaches the localizer: `delivered` is then the localizer's count of NaN
  // odometry (deliver). Members in this order: the writer goes first.
  struct DeliveringWriter {
    std::unique_ptr<dds::Participant> participant;
    dds::Writer odometry;
    std::uint64_t delivered = 0;
  };
  // Created again, participant and all, said on stdout, when the writer never matches in 15 s or,
  // matched, delivers nothing in 15 s more: Fast DDS 2.9 now and then leaves a secured pair of
  // participants mute (docs/security.md), which is not what these tests are about. A new writer
  // alone was not enough (CI saw one never match twice in a row with the same participant); a new
  // participant starts the authentication and the key exchange afresh. Three failures give an
  // empty writer, delivered 0.
  DeliveringWriter delivering_odometry_writer(const DiagnosticsRecorder& d, const dds::DdsOptions& options,
                                              const std::string& name, const std::string& robot) {
    constexpr int kAttempts = 3;
    for (int attempt = 1; attempt <= kAttempts; ++attempt) {
      DeliveringWriter w;
      w.participant = std::make_unique<dds::Participant>(options, name);
      w.odometry = w.participant->robot_writer<msg::OdometryPubSubType>(dds::kOdometryTopic, robot);
      const bool matched = dds::wait_for_matched_readers({w.odometry}, scaled(std::chrono::seconds(15)));
      if (matched) w.delivered = deliver(d, w.odometry, robot);
      if (w.delivered > 0) return w;
      std::cout << "the attacker's writer " << (matched ? "never reached the localizer" : "never matched")
                << " (Fast DDS 2.9 secured matching)" << (attempt < kAttempts ? ": participant created again" : "")
                << '\n';
    }
    return {};
  }

  // An attacker whose own access control lets it write `robot`'s odometry (NaN): never matched,
  // nothing of it counted by the localizer.
  void expect_shut_out(const dds::DdsOptions& attacker_options, const std::string& robot,
                       const DiagnosticsRecorder& diagnostics) {
    dds::Participant attacker(attacker_options, "test.attacker");
    auto odometry = attacker.robot_writer<msg::OdometryPubSubType>(dds::kOdometryTopic, robot);
    EXPECT_FALSE(dds::wait_for_matched_readers({odometry}, scaled(5s)))
        << "the attacker's writer was matched";
    write_nan_odometry(odometry, robot, 20);
    EXPECT_EQ(localizer_count(diagnostics, kNanOdometry, 0), 0u);
  }
  // A participant process that must not start: it exits non-zero, its log saying `why`.
  void expect_refused(const std::vector<std::string>& argv, const std::string& why) {
    ChildProcess p(argv, path("refused.log"));
    const auto code = p.wait(scaled(30s));
    ASSERT_TRUE(code) << "it did not stop";
    EXPECT_NE(*code, 0);
    EXPECT_NE(p.log().find(why), std::string::npos) << p.log();
  }

  std::string keystore_;
  dds::DdsOptions secured_;
  std::unique_ptr<ChildProcess> gateway_, decoder_, localizer_;
  int sent_ = 0;
};

TEST_F(Security, AParticipantWithoutCredentialsReadsNoPoseAndInjectsNothing) {
  PoseRecorder poses(secured_);  // the monitor's read-only identity
  DiagnosticsRecorder diagnostics(secured_);
  PoseRecorder outsider_poses(dds_);  // the same domain, no credentials
  DiagnosticsRecorder outsider_diagnostics(dds_);
  ASSERT_NO_FATAL_FAILURE(start_pipeline(poses, &diagnostics));
  dds::Participant outsider(dds_, "test.outsider");
  auto odometry = outsider.robot_writer<msg::OdometryPubSubType>(dds::kOdometryTopic, "robot1");
  auto unpartitioned = outsider.writer<msg::OdometryPubSubType>(dds::kOdometryTopic);
  auto tof = outsider.robot_writer<msg::RawTofPubSubType>(dds::kRawTofTopic, "robot1");
  write_nan_odometry(odometry, "robot1", 50);
  write_nan_odometry(unpartitioned, "robot1", 50);
  RawTofSample bad;
  bad.beacon_id = 1;
  bad.fire_stamp_ns = kNsPerSecond;
  bad.tof_s = std::nan("");
  auto bad_tof = dds::to_msg("robot1", bad);
  for (int i = 0; i < 20; ++i) tof->write(&bad_tof);
  // The deployment went on localizing robot1.
  ASSERT_TRUE(wait_for_pose(poses, "robot1", poses.newest_stamp_ns() + 2 * kNsPerSecond))
      << localizer_->log();
  EXPECT_EQ(localizer_count(diagnostics, kNanOdometry, 0), 0u);
  const auto decoder = wait_for_diagnostics(diagnostics, kDecoder, [](const auto&) { return true; });
  EXPECT_GT(decoder.accepted(), 0u);
  EXPECT_EQ(rejected_count(decoder, "non_finite_tof"), 0u);
  EXPECT_EQ(outsider_poses.count(), 0u) << "an unauthenticated participant read poses";
  EXPECT_TRUE(outsider_diagnostics.latest().empty()) << "an unauthenticated participant read diagnostics";
  for (const dds::Writer* w : {&odometry, &unpartitioned, &tof}) {
    eprosima::fastdds::dds::PublicationMatchedStatus matched;
    (*w)->get_publication_matched_status(matched);
    EXPECT_EQ(matched.total_count, 0) << "an unauthenticated writer was matched";
  }
}

TEST_F(Security, AnotherRobotsGatewayCannotGetSamplesIntoThisRobotsEstimate) {
  PoseRecorder poses(secured_);
  DiagnosticsRecorder diagnostics(secured_);
  ASSERT_NO_FATAL_FAILURE(start_pipeline(poses, &diagnostics));
  // Its own robot's samples reach the localizer (refused for their NaN: counted): the path is up.
  auto robot2 =
      delivering_odometry_writer(diagnostics, as("/beaconloc/gateway/robot2"), "test.robot2_gateway", "robot2");
  ASSERT_GT(robot2.delivered, 0u) << "robot2's gateway never reached the localizer\n" << localizer_->log();
  auto& odometry = robot2.odometry;
  const std::uint64_t delivered = robot2.delivered;
  // Its permissions grant it robot2's partition only.
  EXPECT_THROW((void)robot2.participant->robot_writer<msg::OdometryPubSubType>(dds::kOdometryTopic, "robot1"),
               dds::DdsError);
  EXPECT_THROW((void)robot2.participant->writer<msg::OdometryPubSubType>(dds::kOdometryTopic), dds::DdsError);
  // In its own partition, samples that say robot1: refused by the reader, counted, never fused.
  write_nan_odometry(odometry, "robot1", 20);
  EXPECT_EQ(localizer_count(diagnostics, "sample_for_another_robot", 20), 20u);
  EXPECT_EQ(localizer_count(diagnostics, kNanOdometry, 0, 0ms), delivered);
  // Moved to robot1's partition once matched: Fast DDS's access control refuses the change but
  // keeps the match, so the readers must not believe it; its samples that say robot1 are refused.
  eprosima::fastdds::dds::PublisherQos moved;
  odometry->get_publisher()->get_qos(moved);
  moved.partition().clear();
  moved.partition().push_back(dds::robot_partition("robot1").c_str());
  ASSERT_EQ(const_cast<eprosima::fastdds::dds::Publisher*>(odometry->get_publisher())->set_qos(moved),
            ReturnCode_t::RETCODE_OK);
  std::this_thread::sleep_for(scaled(1s));  // the change announced
  write_nan_odometry(odometry, "robot1", 20);
  EXPECT_EQ(localizer_count(diagnostics, kNanOdometry, 0), delivered) << "a moved writer spoke for robot1";
  EXPECT_EQ(localizer_count(diagnostics, "sample_for_another_robot", 0, 0ms), 40u);
  ASSERT_TRUE(
      wait_for_pose(poses, "robot1", poses.newest_stamp_ns() + kNsPerSecond));  // localized throughout
}

TEST_F(Security, AReadOnlyIdentityCannotPublish) {
  PoseRecorder poses(secured_);
  ASSERT_NO_FATAL_FAILURE(start_pipeline(poses));
  dds::Participant monitor(as("/beaconloc/monitor"), "test.monitor");
  EXPECT_THROW((void)monitor.robot_writer<msg::RawTofPubSubType>(dds::kRawTofTopic, "robot1"), dds::DdsError);
  EXPECT_THROW((void)monitor.robot_writer<msg::OdometryPubSubType>(dds::kOdometryTopic, "robot1"),
               dds::DdsError);
  EXPECT_THROW((void)monitor.writer<msg::PoseEstimatePubSubType>(dds::kPoseEstimateTopic), dds::DdsError);
  EXPECT_THROW((void)monitor.writer<msg::InitialPosePubSubType>(dds::kInitialPoseTopic), dds::DdsError);
  EXPECT_THROW((void)monitor.writer<msg::BeaconMapPubSubType>(dds::kBeaconMapTopic), dds::DdsError);
  EXPECT_GT(poses.count(), 0u);  // and it reads (the recorder holds the same identity)
}

// A stolen read-only identity with permissions of the attacker's own signing, granting robot1's
// gateway topics: its own access control lets it write, the deployment's refuses it.
TEST_F(Security, PermissionsNotSignedByTheDeploymentAreRefused) {
  PoseRecorder poses(secured_);
  DiagnosticsRecorder diagnostics(secured_);
  ASSERT_NO_FATAL_FAILURE(start_pipeline(poses, &diagnostics));
  const std::string forged = path("forged");
  deployment_keys("init " + forged);
  deployment_keys("enclave " + forged + " gateway robot1 --enclave /beaconloc/monitor");
  // Its CA's lists: not ones our identity CA signed.
  fs::remove(fs::path(forged) / "public/crl.pem");
  fs::remove(fs::path(forged) / "enclaves/beaconloc/monitor/crl.pem");
  for (const char* file : {"cert.pem", "key.pem", "identity_ca.cert.pem"}) {
    fs::copy_file(fs::path(keystore_) / "enclaves/beaconloc/monitor" / file,
                  fs::path(forged) / "enclaves/beaconloc/monitor" / file,
                  fs::copy_options::overwrite_existing);
  }
  dds::DdsOptions o = as("/beaconloc/monitor");
  o.security.keystore = forged;
  expect_shut_out(o, "robot1", diagnostics);
}

// Revoked by the CRL the deployment re-issued: a participant still holding the keystore from
// before (its old CRL) is refused by every participant started with the new one.
TEST_F(Security, ARevokedIdentityIsShutOut) {
  // Under the sanitizers: Fast DDS 2.9.1 leaks the certificate of each handshake it refuses
  // (tests/support/fastdds_refused_handshake.supp says where). The refusing participants are the
  // pipeline's processes, told so, with the full stacks the suppression needs (libcrypto has no
  // frame pointers); this process's readers hold the keystore from before the revocation, so that
  // none of this process's participants refuses one of its own.
  const ScopedEnv lsan("LSAN_OPTIONS", ScopedEnv::with_option(
                                           "LSAN_OPTIONS", "suppressions=" BEACONLOC_SOURCE_DIR
                                                           "/tests/support/fastdds_refused_handshake.supp"));
  const ScopedEnv asan("ASAN_OPTIONS", ScopedEnv::with_option("ASAN_OPTIONS", "fast_unwind_on_malloc=0"));
  const std::string before = path("keystore-before");
  fs::copy(keystore_, before, fs::copy_options::recursive);
  deployment_keys("revoke " + keystore_ + " /beaconloc/gateway/robot2");
  dds::DdsOptions old = secured_;
  old.security.keystore = before;
  PoseRecorder poses(old);
  DiagnosticsRecorder diagnostics(old);
  ASSERT_NO_FATAL_FAILURE(start_pipeline(poses, &diagnostics));  // with the new keystore
  dds::DdsOptions o = as("/beaconloc/gateway/robot2");
  o.security.keystore = before;
  expect_shut_out(o, "robot2", diagnostics);
  // Started with the new keystore, it does not start at all, and says why.
  expect_refused(command("gateway", {"--keystore", keystore_, "--robot", "robot2"}), "certificate revoked");
}

TEST_F(Security, AnExpiredIdentityDoesNotStartAndSaysWhy) {
  deployment_keys("enclave " + keystore_ + " decoder --enclave /expired --not-before 20200101000000Z " +
                  "--not-after 20200201000000Z");
  expect_refused(command("decoder", {"--keystore", keystore_, "--enclave", "/expired"}),
                 "expired on Feb  1 00:00:00 2020 GMT");
}

// robot2's gateway identity whose messages are altered on the wire once it is matched: the
// localizer drops every altered message (its authentication tag fails) and counts it.
TEST_F(Security, TamperedMessagesAreDroppedAndCounted) {
  PoseRecorder poses(secured_);
  DiagnosticsRecorder diagnostics(secured_);
  ASSERT_NO_FATAL_FAILURE(start_pipeline(poses, &diagnostics));
  auto tamper = std::make_shared<TamperingSwitch>();
  dds::DdsOptions o = as("/beaconloc/gateway/robot2");
  o.transport = std::make_shared<TamperingTransportDescriptor>(tamper);
  // Intact, its samples arrive (refused for their NaN: counted).
  auto robot2 = delivering_odometry_writer(diagnostics, o, "test.tampered", "robot2");
  ASSERT_GT(robot2.delivered, 0u) << "robot2's gateway never reached the localizer\n" << localizer_->log();
  const auto& odometry = robot2.odometry;
  const std::uint64_t delivered = robot2.delivered;
  EXPECT_EQ(localizer_count(diagnostics, "undecodable_secure_message", 0, 0ms), 0u);
  tamper->on = true;
  write_nan_odometry(odometry, "robot2", 20);
  EXPECT_GT(localizer_count(diagnostics, "undecodable_secure_message", 1), 0u);
  EXPECT_EQ(localizer_count(diagnostics, kNanOdometry, 0, 0ms), delivered) << "a tampered sample was taken";
  EXPECT_GT(tamper->tampered.load(), 0u);
}

}  // namespace
}  // namespace beaconloc::testing
