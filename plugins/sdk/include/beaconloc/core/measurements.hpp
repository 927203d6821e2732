#pragma once
// What the estimators are pushed: DDS-free forms of the Odometry and BeaconRange topics.
#include <Eigen/Core>
#include <cstdint>

#include "beaconloc/core/time.hpp"

namespace beaconloc {

inline constexpr std::uint32_t kBeaconUnidentified = 0xFFFFFFFFu;

// Wheel velocities held over the odometry interval that ends at stamp_ns (seed 000, eq. 14).
struct OdometrySample {
  StampNs stamp_ns = 0;
  double wheel_velocity_right_mps = 0.0;
  double wheel_velocity_left_mps = 0.0;
  double wheel_base_m = 0.0;
  Eigen::Matrix2d wheel_velocity_covariance = Eigen::Matrix2d::Zero();  // U_k of eq. 16
};

struct RangeMeasurement {
  StampNs stamp_ns = 0;  // arrival of the pulse
  std::uint32_t beacon_id = kBeaconUnidentified;
  std::uint32_t receiver_id = 0;
  double range_m = 0.0;
  double variance_m2 = 0.0;
};

}  // namespace beaconloc

namespace beaconloc {

// DDS-free form of the RawTof topic: one receiver hearing one beacon firing.
struct RawTofSample {
  std::uint32_t beacon_id = kBeaconUnidentified;
  std::uint32_t receiver_id = 0;
  StampNs fire_stamp_ns = 0;
  double tof_s = 0.0;
  double beacon_temperature_c = 0.0;
  std::uint64_t sequence_number = 0;
};

}  // namespace beaconloc

#include <vector>

namespace beaconloc {

// Whether a pulse came as beacon 1's double burst (seed 002 Fig. 2), where the receiver hardware
// tells: an explicit third value, not a default that reads as "single".
enum class PulseMark : std::uint8_t {
  kNotReported,  // the hardware does not tell single from double bursts
  kSingle,
  kDouble,
};

// Stable names, as recordings write them ("not_reported", "single", "double").
inline const char* to_string(PulseMark m) {
  switch (m) {
    case PulseMark::kSingle:
      return "single";
    case PulseMark::kDouble:
      return "double";
    case PulseMark::kNotReported:
      break;
  }
  return "not_reported";
}

// DDS-free form of the PulseArrival topic: one receiver hearing an ultrasonic pulse from a
// beacon that sends neither its id nor its firing time (seed 002 Sec. 2): the arrival time in the
// receiver's clock, the robot's (the clock its odometry is stamped with), and nothing else.
struct PulseArrivalSample {
  StampNs stamp_ns = 0;  // arrival of the pulse (the start of its envelope)
  std::uint32_t receiver_id = 0;
  PulseMark mark = PulseMark::kNotReported;
  std::uint64_t sequence_number = 0;
};

// DDS-free form of the LaserScan topic. Beam i points at angle_min_rad + i * angle_increment_rad
// in the robot frame; a range outside [range_min_m, range_max_m] (e.g. +inf) is no return.
struct LaserScanSample {
  StampNs stamp_ns = 0;
  float angle_min_rad = 0.0f;
  float angle_increment_rad = 0.0f;
  float range_min_m = 0.0f;
  float range_max_m = 0.0f;
  std::vector<float> ranges_m;
};

}  // namespace beaconloc
