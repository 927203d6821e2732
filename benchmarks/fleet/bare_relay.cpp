#include "bare_relay.hpp"

#include <beaconlocPubSubTypes.h>

#include <algorithm>

#include "beaconloc/dds/topics.hpp"

namespace beaconloc::bench {

BareRelay::BareRelay(const dds::DdsOptions& dds)
    : participant_(dds, "beaconloc.bench.bare_relay"),
      pose_writer_(participant_.writer<msg::PoseEstimatePubSubType>(dds::kPoseEstimateTopic)),
      odometry_reader_(participant_.subscribe<msg::OdometryPubSubType>(
          dds::kOdometryTopic,
          [this](const msg::Odometry& m) {
            {
              std::lock_guard<std::mutex> lock(mutex_);
              auto [last, first] = odometry_sequence_.try_emplace(m.robot_id(), m.sequence_number());
              if (!first && m.sequence_number() > last->second) {
                lost_increments_ += m.sequence_number() - last->second - 1;
                last->second = m.sequence_number();
              }
              odometry_stamp_ns_[m.robot_id()] = m.stamp_ns();
              write_pose(m.robot_id(), m.stamp_ns());
              newest_odometry_stamp_ns_ = std::max(newest_odometry_stamp_ns_.load(), m.stamp_ns());
            }
            ++odometry_processed_;
          })),
      range_reader_(participant_.subscribe<msg::BeaconRangePubSubType>(
          dds::kBeaconRangeTopic, [this](const msg::BeaconRange& m) {
            std::lock_guard<std::mutex> lock(mutex_);
            const auto stamp = odometry_stamp_ns_.find(m.robot_id());
            if (stamp != odometry_stamp_ns_.end()) write_pose(m.robot_id(), stamp->second);
          })) {}

void BareRelay::write_pose(const std::string& robot_id, StampNs stamp_ns) {
  msg::PoseEstimate p;
  p.robot_id(robot_id);
  p.stamp_ns(stamp_ns);
  p.estimator("bare");
  p.status(msg::POSE_STATUS_OK);
  pose_writer_->write(&p);
  ++poses_written_;
}

}  // namespace beaconloc::bench
