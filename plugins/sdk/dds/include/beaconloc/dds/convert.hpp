#pragma once
// Conversions between the wire types (idl/beaconloc.idl) and the DDS-free core types.
#include <beaconloc.h>

#include <string>
#include <vector>

#include "beaconloc/core/beacon_calibration.hpp"
#include "beaconloc/core/beacon_map.hpp"
#include "beaconloc/core/estimator.hpp"
#include "beaconloc/core/measurements.hpp"
#include "beaconloc/core/rejection_counter.hpp"

namespace beaconloc::dds {

RawTofSample from_msg(const msg::RawTof& m);
msg::RawTof to_msg(const std::string& robot_id, const RawTofSample& s);
// A mark the IDL does not define never gets here (checked_type.hpp refuses the sample).
PulseArrivalSample from_msg(const msg::PulseArrival& m);
msg::PulseArrival to_msg(const std::string& robot_id, const PulseArrivalSample& s);

OdometrySample from_msg(const msg::Odometry& m);
msg::Odometry to_msg(const std::string& robot_id, const OdometrySample& s, std::uint64_t sequence);

RangeMeasurement from_msg(const msg::BeaconRange& m);

LaserScanSample from_msg(const msg::LaserScan& m);
msg::LaserScan to_msg(const std::string& robot_id, const LaserScanSample& s);

// The beacons of a BeaconMap sample as sent, unchecked, each in the list of its frame: the core's
// set_beacon_map checks them (check_beacons) and counts a refused map as beacon_map.<reason>. (A
// frame the IDL does not define never gets here: checked_type.hpp refuses the sample.)
BeaconList from_msg(const msg::BeaconMap& m);
msg::BeaconMap to_msg(const BeaconMap& map, const std::string& frame_id);

// A BeaconCalibration sample as sent, unchecked: the core checks it (check_calibration) and
// counts a refused one as calibration.<reason>.
BeaconCalibration from_msg(const msg::BeaconCalibration& m);
msg::BeaconCalibration to_msg(const BeaconCalibration& calibration, const std::string& frame_id);

msg::PoseEstimate to_msg(const std::string& robot_id, const PoseEstimate& estimate,
                         const std::string& estimator, const std::vector<std::uint32_t>& beacons_used);
PoseEstimate from_msg(const msg::PoseEstimate& m);

msg::PoseStatus to_msg(PoseStatus s);
PoseStatus from_msg(msg::PoseStatus s);

msg::Diagnostics make_diagnostics(const std::string& participant, StampNs stamp_ns,
                                  const RejectionCounter& counts, std::uint64_t deadline_misses,
                                  msg::ParticipantStatus status, const std::string& message);

}  // namespace beaconloc::dds
