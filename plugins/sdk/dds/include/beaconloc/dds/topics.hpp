#pragma once
// DDS topic names of the beaconloc bus and the QoS profile of each (examples/qos/topics.xml).
namespace beaconloc::dds {

struct TopicSpec {
  const char* name;
  const char* writer_profile;
  const char* reader_profile;
};

inline constexpr TopicSpec kRawTofTopic{"beaconloc/raw_tof", "raw_tof.writer", "raw_tof.reader"};
inline constexpr TopicSpec kPulseArrivalTopic{"beaconloc/pulse_arrival", "pulse_arrival.writer",
                                              "pulse_arrival.reader"};
inline constexpr TopicSpec kBeaconRangeTopic{"beaconloc/beacon_range", "beacon_range.writer",
                                             "beacon_range.reader"};
inline constexpr TopicSpec kOdometryTopic{"beaconloc/odometry", "odometry.writer", "odometry.reader"};
inline constexpr TopicSpec kLaserScanTopic{"beaconloc/laser_scan", "laser_scan.writer", "laser_scan.reader"};
inline constexpr TopicSpec kPoseEstimateTopic{"beaconloc/pose_estimate", "pose_estimate.writer",
                                              "pose_estimate.reader"};
inline constexpr TopicSpec kEstimatorStateTopic{"beaconloc/estimator_state", "estimator_state.writer",
                                                "estimator_state.reader"};
inline constexpr TopicSpec kInitialPoseTopic{"beaconloc/initial_pose", "initial_pose.writer",
                                             "initial_pose.reader"};
inline constexpr TopicSpec kBeaconMapTopic{"beaconloc/beacon_map", "beacon_map.writer", "beacon_map.reader"};
inline constexpr TopicSpec kBeaconCalibrationTopic{"beaconloc/beacon_calibration", "beacon_calibration.writer",
                                                   "beacon_calibration.reader"};
inline constexpr TopicSpec kFiringPlanTopic{"beaconloc/firing_plan", "firing_plan.writer", "firing_plan.reader"};
inline constexpr TopicSpec kDiagnosticsTopic{"beaconloc/diagnostics", "diagnostics.writer",
                                             "diagnostics.reader"};

}  // namespace beaconloc::dds
