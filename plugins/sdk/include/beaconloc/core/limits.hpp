#pragma once
// Physical bounds on what the sensors can report, defined once: a number beyond them is no
// measurement (a corrupted file, a unit mix-up, a hostile sample) and is refused with a reason
// by whoever reads it first (the replay reader, the estimators, the bridge). They are far beyond
// any robot this serves, so no real measurement comes near them.
namespace beaconloc {

// A wheel's ground speed: indoor robots drive at up to 2-3 m/s; 10 m/s is 36 km/h.
inline constexpr double kMaxWheelSpeedMps = 10.0;
// The distance between the two drive wheels: large AGVs have 2 m.
inline constexpr double kMaxWheelBaseM = 10.0;
// A beacon range: ultrasonic beacons reach 15 m, the radio beacons of the CMU recordings 150 m.
inline constexpr double kMaxRangeM = 1000.0;

}  // namespace beaconloc
