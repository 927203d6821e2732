#pragma once
// Physical limits of the robots and sites beaconloc serves, defined once: every number read from
// a file, an option or the bus that stands for one of these quantities is refused beyond them
// (with a reason naming the field), so that no absurd value reaches an estimator.
#include "beaconloc/core/time.hpp"

namespace beaconloc {

// How old a beacon measurement may be and still be fused, against the newest data (ns): three
// 200 ms beacon slots; an older TOF describes a pose the robot has left (0.34 m/s x 0.6 s =
// 0.2 m). The decoder's stale TOF age, the out-of-sequence fusion's horizon, range_ekf's stale
// range age, and the raw_tof and beacon_range lifespans of examples/qos/topics.xml
// (unit.QosProfiles.TheMeasurementLifespansAreTheHorizon checks the file against it).
inline constexpr StampNs kMeasurementHorizonNs = 600 * kNsPerMillisecond;

// A wheel's speed over the floor, either way (m/s): odometry rows, simulated trajectories.
inline constexpr double kMaxWheelSpeedMps = 10.0;
// The distance between a robot's wheels (m).
inline constexpr double kMaxWheelBaseM = 10.0;
// How far a receiver sits from the robot's centre, along each axis and in height (m).
inline constexpr double kMaxReceiverOffsetM = 10.0;
// A map-frame coordinate (m): beacon positions, truth and estimated positions, map origins,
// initial poses. 1000 km: any site, far from where a double loses centimetres.
inline constexpr double kMaxMapCoordinateM = 1e6;
// An angle read from a file (rad): headings may be unwrapped, but not beyond this.
inline constexpr double kMaxAngleRad = 1e6;
// The longest range a beacon system measures (m): ultrasonic beacons reach 15 m, the radio
// beacons of the CMU recordings 150 m.
inline constexpr double kMaxRangeM = 1e4;
// The longest run, simulated or replayed (s): 11.6 days, far within the int64 ns clock.
inline constexpr double kMaxDurationS = 1e6;
// A time stamp read from a file, in seconds of the recording's clock: within [0, 4.6e9] (146
// years), so that a stamp, and a stamp minus a time of flight as long, are int64 nanoseconds.
inline constexpr double kMaxFileStampS = 4.6e9;

}  // namespace beaconloc
