#pragma once
// The state of seed 002's filter (eq. 14): x = [x_pos, y_pos, v, theta, T, t0, s], the robot's
// position (m, map frame), speed (m/s) and heading (rad), the beacons' cycle time (one slot, s),
// the firing time of the filter's current slot (s, receiver clock, from the estimator's epoch)
// and the speed of sound (m/s). ArrivalTimeIndex (core/models/arrival_time_model.hpp) names the
// same places for eq. 21.
#include "beaconloc/core/filters/state_space.hpp"
#include "beaconloc/core/models/arrival_time_model.hpp"

namespace beaconloc::kleeman {

inline constexpr int kStateSize = 7;
using State = Vec<kStateSize>;
using Covariance = Mat<kStateSize, kStateSize>;

enum Index : Eigen::Index {
  kX = 0,
  kY = 1,
  kSpeed = 2,
  kHeading = 3,
  kCycle = 4,
  kFireTime = 5,
  kSpeedOfSound = 6,
};

inline ArrivalTimeIndex arrival_time_index() { return {kX, kY, kSpeed, kHeading, kFireTime, kSpeedOfSound}; }

// theta is the one angle: wrapped by the filter's state space and nowhere else.
inline StateSpace<kStateSize> state_space() { return StateSpace<kStateSize>({kHeading}); }

}  // namespace beaconloc::kleeman
