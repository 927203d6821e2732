#include "localizer_participant.hpp"

#include <beaconlocPubSubTypes.h>

#include "beaconloc/dds/convert.hpp"
#include "beaconloc/dds/wall_clock.hpp"

namespace beaconloc {

LocalizerParticipant::LocalizerParticipant(const dds::DdsOptions& dds, LocalizerCore core)
    : core_(std::move(core)),
      participant_(dds, "beaconloc.localizer." + core_.estimator_name()),
      pose_writer_(participant_.writer<msg::PoseEstimatePubSubType>(dds::kPoseEstimateTopic)) {
  participant_.subscribe<msg::BeaconMapPubSubType>(dds::kBeaconMapTopic, [this](const msg::BeaconMap& m) {
    std::lock_guard<std::mutex> lock(mutex_);
    core_.set_beacon_map(dds::from_msg(m));
  });
  participant_.subscribe<msg::BeaconRangePubSubType>(
      dds::kBeaconRangeTopic,
      [this](const msg::BeaconRange& m) {
        {
          std::lock_guard<std::mutex> lock(mutex_);
          core_.on_range(m.robot_id(), dds::from_msg(m));
        }
        ++ranges_processed_;
      },
      &deadline_misses_);
  participant_.subscribe<msg::OdometryPubSubType>(
      dds::kOdometryTopic, [this](const msg::Odometry& m) { on_odometry(m); }, &deadline_misses_);
  if (core_.uses_laser()) {
    participant_.subscribe<msg::LaserScanPubSubType>(dds::kLaserScanTopic, [this](const msg::LaserScan& m) {
      std::lock_guard<std::mutex> lock(mutex_);
      core_.on_laser(m.robot_id(), dds::from_msg(m));
    });
  }
  participant_.subscribe<msg::InitialPosePubSubType>(
      dds::kInitialPoseTopic, [this](const msg::InitialPose& m) {
        Cov3 c;
        for (int i = 0; i < 9; ++i) c(i / 3, i % 3) = m.covariance()[static_cast<std::size_t>(i)];
        std::lock_guard<std::mutex> lock(mutex_);
        core_.on_initial_pose(m.robot_id(), m.stamp_ns(), Pose2(m.x_m(), m.y_m(), m.yaw_rad()), c);
      });
  diagnostics_ =
      std::make_unique<dds::DiagnosticsPublisher>(participant_, [this] { return diagnostics_snapshot(); });
}

LocalizerParticipant::~LocalizerParticipant() {
  diagnostics_->stop();
  participant_.close();
}

void LocalizerParticipant::on_odometry(const msg::Odometry& m) {
  std::optional<LocalizerOutput> out;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    out = core_.on_odometry(m.robot_id(), dds::from_msg(m));
  }
  if (out) {
    auto p = dds::to_msg(out->robot_id, out->estimate, core_.estimator_name(), out->beacons_used);
    pose_writer_->write(&p);
  }
  ++odometry_processed_;
}

msg::Diagnostics LocalizerParticipant::diagnostics_snapshot() {
  std::lock_guard<std::mutex> lock(mutex_);
  const PoseStatus worst = core_.worst_status();
  msg::ParticipantStatus status = msg::PARTICIPANT_STATUS_OK;
  std::string message =
      std::to_string(core_.robot_count()) + " robot(s), worst pose status " + to_string(worst);
  if (!core_.has_beacon_map()) {
    status = msg::PARTICIPANT_STATUS_DEGRADED;
    message = "waiting for the beacon map";
  } else if (worst == PoseStatus::kDegraded || worst == PoseStatus::kLost) {
    status = msg::PARTICIPANT_STATUS_DEGRADED;
  }
  return dds::make_diagnostics(participant_.name(), dds::wall_clock_ns(), core_.counts(),
                               deadline_misses_.load(), status, message);
}

}  // namespace beaconloc
