#pragma once
// DDS topic names of the beaconloc bus, the QoS profile of each (examples/qos/topics.xml), and
// the deadline its readers keep.
#include <cstdint>

namespace beaconloc::dds {

struct TopicSpec {
  const char* name;
  const char* writer_profile;
  const char* reader_profile;
  // How long a robot may go without a sample before the reader reports a missed deadline (0:
  // never). Kept by the reader (SampleListener, core/deadline_watch.hpp), not by the deadline
  // QoS: Fast DDS 2.9 looks through every robot's instance on each sample of a keyed topic with
  // a deadline, which made a localizer's cost per sample grow with the fleet (BENCHMARKS.md
  // section 3). The profiles in topics.xml therefore set no deadline.
  std::int64_t deadline_ns = 0;
  // A robot's own measurements: written in the robot's partition (dds::robot_partition), read from
  // a writer only for the robots of its partitions (dds::Participant::subscribe).
  bool per_robot = false;
};

inline constexpr bool kPerRobot = true;

// Two 200 ms beacon slots (under three of seed 002's 150 ms pulse slots): a gateway whose TOFs or
// pulses (or the decoder whose ranges) stopped is noticed within two slots.
inline constexpr std::int64_t kBeaconMeasurementDeadlineNs = 400'000'000;
// Five 10 ms odometry periods: odometry stopping is a fault to report quickly.
inline constexpr std::int64_t kOdometryDeadlineNs = 50'000'000;

inline constexpr TopicSpec kRawTofTopic{"beaconloc/raw_tof", "raw_tof.writer", "raw_tof.reader",
                                        kBeaconMeasurementDeadlineNs, kPerRobot};
inline constexpr TopicSpec kPulseArrivalTopic{"beaconloc/pulse_arrival", "pulse_arrival.writer",
                                              "pulse_arrival.reader", kBeaconMeasurementDeadlineNs, kPerRobot};
inline constexpr TopicSpec kBeaconRangeTopic{"beaconloc/beacon_range", "beacon_range.writer",
                                             "beacon_range.reader", kBeaconMeasurementDeadlineNs};
inline constexpr TopicSpec kOdometryTopic{"beaconloc/odometry", "odometry.writer", "odometry.reader",
                                          kOdometryDeadlineNs, kPerRobot};
inline constexpr TopicSpec kLaserScanTopic{"beaconloc/laser_scan", "laser_scan.writer", "laser_scan.reader", 0,
                                           kPerRobot};
inline constexpr TopicSpec kPoseEstimateTopic{"beaconloc/pose_estimate", "pose_estimate.writer",
                                              "pose_estimate.reader"};
inline constexpr TopicSpec kEstimatorStateTopic{"beaconloc/estimator_state", "estimator_state.writer",
                                                "estimator_state.reader"};
// Per robot: an initial pose places one robot's estimate (its bridge's /initialpose).
inline constexpr TopicSpec kInitialPoseTopic{"beaconloc/initial_pose", "initial_pose.writer",
                                             "initial_pose.reader", 0, kPerRobot};
inline constexpr TopicSpec kBeaconMapTopic{"beaconloc/beacon_map", "beacon_map.writer", "beacon_map.reader"};
inline constexpr TopicSpec kBeaconCalibrationTopic{"beaconloc/beacon_calibration", "beacon_calibration.writer",
                                                   "beacon_calibration.reader"};
inline constexpr TopicSpec kFiringPlanTopic{"beaconloc/firing_plan", "firing_plan.writer", "firing_plan.reader"};
inline constexpr TopicSpec kDiagnosticsTopic{"beaconloc/diagnostics", "diagnostics.writer",
                                             "diagnostics.reader"};
inline constexpr TopicSpec kLocalizerShardTopic{"beaconloc/localizer_shard", "localizer_shard.writer",
                                                "localizer_shard.reader"};

}  // namespace beaconloc::dds
