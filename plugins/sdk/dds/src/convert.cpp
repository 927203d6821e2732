#include "beaconloc/dds/convert.hpp"

namespace beaconloc::dds {

RawTofSample from_msg(const msg::RawTof& m) {
  RawTofSample s;
  s.beacon_id = m.beacon_id();
  s.receiver_id = m.receiver_id();
  s.fire_stamp_ns = m.fire_stamp_ns();
  s.tof_s = m.tof_s();
  s.beacon_temperature_c = m.beacon_temperature_c();
  s.sequence_number = m.sequence_number();
  return s;
}

msg::RawTof to_msg(const std::string& robot_id, const RawTofSample& s) {
  msg::RawTof m;
  m.robot_id(robot_id);
  m.beacon_id(s.beacon_id);
  m.receiver_id(s.receiver_id);
  m.fire_stamp_ns(s.fire_stamp_ns);
  m.tof_s(s.tof_s);
  m.beacon_temperature_c(s.beacon_temperature_c);
  m.sequence_number(s.sequence_number);
  return m;
}

namespace {
PulseMark from_msg(msg::PulseMark m) {
  switch (m) {
    case msg::PULSE_MARK_SINGLE:
      return PulseMark::kSingle;
    case msg::PULSE_MARK_DOUBLE:
      return PulseMark::kDouble;
    case msg::PULSE_MARK_NOT_REPORTED:
      break;
  }
  return PulseMark::kNotReported;
}

msg::PulseMark to_msg(PulseMark m) {
  switch (m) {
    case PulseMark::kSingle:
      return msg::PULSE_MARK_SINGLE;
    case PulseMark::kDouble:
      return msg::PULSE_MARK_DOUBLE;
    case PulseMark::kNotReported:
      break;
  }
  return msg::PULSE_MARK_NOT_REPORTED;
}
}  // namespace

PulseArrivalSample from_msg(const msg::PulseArrival& m) {
  PulseArrivalSample s;
  s.stamp_ns = m.arrival_stamp_ns();
  s.receiver_id = m.receiver_id();
  s.mark = from_msg(m.mark());
  s.sequence_number = m.sequence_number();
  return s;
}

msg::PulseArrival to_msg(const std::string& robot_id, const PulseArrivalSample& s) {
  msg::PulseArrival m;
  m.robot_id(robot_id);
  m.receiver_id(s.receiver_id);
  m.arrival_stamp_ns(s.stamp_ns);
  m.mark(to_msg(s.mark));
  m.sequence_number(s.sequence_number);
  return m;
}

OdometrySample from_msg(const msg::Odometry& m) {
  OdometrySample s;
  s.stamp_ns = m.stamp_ns();
  s.wheel_velocity_right_mps = m.wheel_velocity_right_mps();
  s.wheel_velocity_left_mps = m.wheel_velocity_left_mps();
  s.wheel_base_m = m.wheel_base_m();
  const auto& c = m.wheel_velocity_covariance_m2ps2();
  s.wheel_velocity_covariance << c[0], c[1], c[2], c[3];
  return s;
}

msg::Odometry to_msg(const std::string& robot_id, const OdometrySample& s, std::uint64_t sequence) {
  msg::Odometry m;
  m.robot_id(robot_id);
  m.stamp_ns(s.stamp_ns);
  m.wheel_velocity_right_mps(s.wheel_velocity_right_mps);
  m.wheel_velocity_left_mps(s.wheel_velocity_left_mps);
  m.wheel_base_m(s.wheel_base_m);
  const auto& c = s.wheel_velocity_covariance;
  m.wheel_velocity_covariance_m2ps2({c(0, 0), c(0, 1), c(1, 0), c(1, 1)});
  m.sequence_number(sequence);
  return m;
}

RangeMeasurement from_msg(const msg::BeaconRange& m) {
  RangeMeasurement r;
  r.stamp_ns = m.stamp_ns();
  r.beacon_id = m.association() == msg::RANGE_ASSOCIATION_UNASSOCIATED ? kBeaconUnidentified : m.beacon_id();
  r.receiver_id = m.receiver_id();
  r.range_m = m.range_m();
  r.variance_m2 = m.variance_m2();
  return r;
}

LaserScanSample from_msg(const msg::LaserScan& m) {
  LaserScanSample s;
  s.stamp_ns = m.stamp_ns();
  s.angle_min_rad = m.angle_min_rad();
  s.angle_increment_rad = m.angle_increment_rad();
  s.range_min_m = m.range_min_m();
  s.range_max_m = m.range_max_m();
  s.ranges_m = m.ranges_m();
  return s;
}

msg::LaserScan to_msg(const std::string& robot_id, const LaserScanSample& s) {
  msg::LaserScan m;
  m.robot_id(robot_id);
  m.stamp_ns(s.stamp_ns);
  m.angle_min_rad(s.angle_min_rad);
  m.angle_increment_rad(s.angle_increment_rad);
  m.range_min_m(s.range_min_m);
  m.range_max_m(s.range_max_m);
  m.ranges_m(s.ranges_m);
  return m;
}

BeaconList from_msg(const msg::BeaconMap& m) {
  BeaconList beacons;
  for (const auto& b : m.beacons()) {
    const Eigen::Vector3d position_m(b.x_m(), b.y_m(), b.z_m());
    switch (b.frame()) {  // a frame the IDL does not define never gets here (checked_type.hpp)
      case msg::BEACON_FRAME_GROUP:
        beacons.group_frame.push_back({b.id(), b.group(), position_m});
        break;
      case msg::BEACON_FRAME_MAP:
        beacons.map_frame.push_back({b.id(), position_m, b.group()});
        break;
    }
    // All zero: not known (the default). Anything else is the beacon's reach, checked with the
    // map (check_beacons: bad_reach), not repaired here.
    const BeaconReach reach{b.min_range_m(), b.max_range_m(), b.beam_half_angle_rad()};
    if (reach != BeaconReach{}) beacons.reach[b.id()] = reach;
  }
  return beacons;
}

namespace {

msg::Beacon beacon_msg(std::uint32_t id, const Eigen::Vector3d& position_m, std::uint32_t group, msg::BeaconFrame frame,
                       const BeaconReach& reach) {
  msg::Beacon mb;
  mb.min_range_m(reach.min_range_m);
  mb.max_range_m(reach.max_range_m);
  mb.beam_half_angle_rad(reach.beam_half_angle_rad);
  mb.id(id);
  mb.x_m(position_m.x());
  mb.y_m(position_m.y());
  mb.z_m(position_m.z());
  mb.group(group);
  mb.frame(frame);
  return mb;
}

}  // namespace

msg::BeaconMap to_msg(const BeaconMap& map, const std::string& frame_id) {
  msg::BeaconMap m;
  m.frame_id(frame_id);
  for (const Beacon& b : map.beacons()) {
    m.beacons().push_back(beacon_msg(b.id, b.position_map_m, b.group, msg::BEACON_FRAME_MAP, map.reach_of(b.id)));
  }
  for (const LocalBeacon& b : map.local_beacons()) {
    m.beacons().push_back(beacon_msg(b.id, b.position_group_m, b.group, msg::BEACON_FRAME_GROUP, map.reach_of(b.id)));
  }
  return m;
}

BeaconCalibration from_msg(const msg::BeaconCalibration& m) {
  BeaconCalibration c;
  for (const msg::GroupCalibration& mg : m.groups()) {
    GroupCalibration g;
    g.group = mg.group();
    g.stamp_ns = mg.stamp_ns();
    g.transform = Eigen::Vector4d(mg.a(), mg.b(), mg.tx_m(), mg.ty_m());
    g.mean_error_m = mg.mean_error_m();
    for (const msg::CalibratedBeacon& mb : mg.beacons()) {
      CalibratedBeacon b;
      b.id = mb.id();
      b.position_map_m = Eigen::Vector3d(mb.x_m(), mb.y_m(), mb.z_m());
      b.covariance_m2 = Eigen::Map<const Eigen::Matrix<double, 2, 2, Eigen::RowMajor>>(mb.covariance_m2().data());
      g.beacons.push_back(b);
    }
    c.groups.push_back(std::move(g));
  }
  return c;
}

msg::BeaconCalibration to_msg(const BeaconCalibration& c, const std::string& frame_id) {
  msg::BeaconCalibration m;
  m.frame_id(frame_id);
  for (const GroupCalibration& g : c.groups) {
    msg::GroupCalibration mg;
    mg.group(g.group);
    mg.stamp_ns(g.stamp_ns);
    mg.a(g.transform(0));
    mg.b(g.transform(1));
    mg.tx_m(g.transform(2));
    mg.ty_m(g.transform(3));
    mg.mean_error_m(g.mean_error_m);
    for (const CalibratedBeacon& b : g.beacons) {
      msg::CalibratedBeacon mb;
      mb.id(b.id);
      mb.x_m(b.position_map_m.x());
      mb.y_m(b.position_map_m.y());
      mb.z_m(b.position_map_m.z());
      std::array<double, 4> covariance{};
      Eigen::Map<Eigen::Matrix<double, 2, 2, Eigen::RowMajor>>(covariance.data()) = b.covariance_m2;
      mb.covariance_m2(covariance);
      mg.beacons().push_back(mb);
    }
    m.groups().push_back(std::move(mg));
  }
  return m;
}

msg::PoseEstimate to_msg(const std::string& robot_id, const PoseEstimate& e, const std::string& estimator,
                         const std::vector<std::uint32_t>& beacons_used) {
  msg::PoseEstimate m;
  m.robot_id(robot_id);
  m.stamp_ns(e.stamp_ns);
  m.x_m(e.pose_map_base.x());
  m.y_m(e.pose_map_base.y());
  m.yaw_rad(e.pose_map_base.z());
  std::array<double, 9> covariance{};
  Eigen::Map<Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(covariance.data()) = e.covariance;
  m.covariance(covariance);
  m.estimator(estimator);
  m.status(to_msg(e.status));
  m.beacons_used(beacons_used);
  return m;
}

PoseEstimate from_msg(const msg::PoseEstimate& m) {
  PoseEstimate e;
  e.stamp_ns = m.stamp_ns();
  e.pose_map_base = {m.x_m(), m.y_m(), m.yaw_rad()};
  e.covariance = Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(m.covariance().data());
  e.status = from_msg(m.status());
  return e;
}

msg::PoseStatus to_msg(PoseStatus s) {
  switch (s) {
    case PoseStatus::kInitializing:
      return msg::POSE_STATUS_INITIALIZING;
    case PoseStatus::kOk:
      return msg::POSE_STATUS_OK;
    case PoseStatus::kDegraded:
      return msg::POSE_STATUS_DEGRADED;
    case PoseStatus::kLost:
      return msg::POSE_STATUS_LOST;
  }
  return msg::POSE_STATUS_LOST;
}

PoseStatus from_msg(msg::PoseStatus s) {
  switch (s) {
    case msg::POSE_STATUS_INITIALIZING:
      return PoseStatus::kInitializing;
    case msg::POSE_STATUS_OK:
      return PoseStatus::kOk;
    case msg::POSE_STATUS_DEGRADED:
      return PoseStatus::kDegraded;
    case msg::POSE_STATUS_LOST:
      return PoseStatus::kLost;
  }
  return PoseStatus::kLost;
}

msg::Diagnostics make_diagnostics(const std::string& participant, StampNs stamp_ns,
                                  const RejectionCounter& counts, std::uint64_t deadline_misses,
                                  msg::ParticipantStatus status, const std::string& message) {
  msg::Diagnostics d;
  d.participant(participant);
  d.stamp_ns(stamp_ns);
  d.accepted(counts.accepted());
  for (const auto& [reason, count] : counts.rejected_by_reason()) {
    msg::RejectionCount rc;
    rc.reason(reason);
    rc.count(count);
    d.rejected().push_back(rc);
  }
  d.deadline_misses(deadline_misses);
  d.status(status);
  d.message(message);
  return d;
}

}  // namespace beaconloc::dds
