#pragma once
// Start-up without a prior (issue 15; seed 002 Sec. 4 gives its filter 15 s standing still
// instead): the robot's pose, the firing time and cycle of the beacons and the speed of sound
// found from the arrival times of a few cycles at once, by least squares.
//
// Each pulse, heard in slot j from beacon b_j, arrived at
//   a_j = t_first + (j - j_first) T + |p(a_j) - b_j| / s                    (eq. 19, 21)
// with p(a_j) the robot's position when the pulse reached it: the pose (x, y, theta) at the
// window's reference time moved by the dead-reckoned displacement since (odometry_track.hpp),
// so a robot that moves during the window is fitted too, and its heading found from how its
// distances to the beacons change. Eq. 21's t_flight solves the same equation for a robot whose
// velocity is in the state; here the position at arrival is known from the odometry.
//
// Unknowns [x, y, theta, t_first, T, s], with priors on T (the nominal slot), s (a nominal
// temperature, Sec. 4's 5 m/s) and a weak one on theta (unobserved while the robot stands).
// Gauss-Newton from a grid of starts over the beacons' extent (and four headings when the robot
// moved), the best kept; then the worst pulse dropped while it misses by more than the outlier
// gate (an echo), and refitted.
#include <cstdint>
#include <string>
#include <vector>

#include "beaconloc/core/filters/state_space.hpp"
#include "kleeman_iekf/odometry_track.hpp"

namespace beaconloc::kleeman {

struct SlotPulse {
  std::int64_t slot = 0;  // in the estimator's numbering of the firings
  double arrival_s = 0.0;
  std::uint32_t beacon_id = 0;
  Eigen::Vector3d beacon_map_m = Eigen::Vector3d::Zero();
};

struct StartupFitSettings {
  double receiver_z_m = 0.0;
  double arrival_sigma_s = 2e-4;
  double outlier_gate_s = 1.5e-3;   // a pulse missing by more is dropped (an echo)
  double speed_of_sound_mps = 343.3;
  double speed_of_sound_sigma_mps = 5.0;
  double cycle_s = 0.15;
  double cycle_sigma_s = 1e-3;
  int min_pulses = 8;
  int min_beacons = 4;
  double heading_observed_after_m = 0.1;  // the robot moved at least this far in the window
};

struct StartupFit {
  enum class Parameter : Eigen::Index { kX, kY, kHeading, kFirstFireTime, kCycle, kSpeedOfSound };
  bool ok = false;
  std::string why_not;            // for people, when !ok
  double reference_s = 0.0;       // the pose is the robot's at this time
  std::int64_t first_slot = 0;    // t_first is this slot's firing time
  Vec<6> solution = Vec<6>::Zero();
  Mat<6, 6> covariance = Mat<6, 6>::Identity();
  bool heading_observed = false;  // else theta is its prior's
  int pulses_used = 0;
  int pulses_dropped = 0;
  double rms_residual_s = 0.0;
};

// pulses: a few cycles of slot-numbered pulses in time order; track: the odometry over them
// (nullptr: the robot stood still). heading_guess_rad: the start of theta when the robot did not
// move (and the centre of its weak prior).
StartupFit fit_startup(const std::vector<SlotPulse>& pulses, const OdometryTrack* track,
                       const StartupFitSettings& settings, double heading_guess_rad = 0.0);

}  // namespace beaconloc::kleeman
