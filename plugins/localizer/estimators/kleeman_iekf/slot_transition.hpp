#pragma once
// Seed 002's state transition over one beacon slot (eq. 15, Jacobian eq. 16), with the
// dead-reckoned heading change as the input (eq. 24) and the process noise of Sec. 3.10.
//
// Deviation from eq. 15: the position moves along the slot's mean heading theta + dtheta/2, not
// theta(k). Over a 0.15 s slot on a 0.5 rad/s corner eq. 15 leaves the position 1.4 mm to the
// outside of the turn per slot (v T^2 omega / 2), the bias the paper sees ("on corners the
// localiser path is on the outside", Sec. 4); the midpoint removes it at no cost. With
// dtheta = 0 both are eq. 15, and the Jacobian below is eq. 16 there.
#include <cmath>

#include "kleeman_iekf/kleeman_state.hpp"

namespace beaconloc::kleeman {

// The per-slot process noise (standard deviations over one slot), Sec. 3.10: the paper picks Q
// from the path planner's motion type; here it is one set for every motion, with the heading's
// from the dead-reckoning input (SlotTransition's input noise).
struct SlotNoise {
  double position_m = 0.002;   // wheel slip the dead reckoning does not see
  double speed_mps = 0.05;     // acceleration over a slot (0.33 m/s^2)
  double cycle_s = 1e-9;       // drift of the beacon controller's clock (a crystal: ppm)
  double fire_time_s = 5e-6;   // jitter of each firing
  // The air's temperature drifting by up to 0.1 C a minute: 0.06 m/s a minute over 400 slots,
  // a random walk of 0.003 m/s a slot.
  double speed_of_sound_mps = 0.003;
};

class SlotTransition {
 public:
  static constexpr int kInputSize = 1;  // dtheta (eq. 24)
  static constexpr bool kHasStateNoise = true;
  using Input = Vec<1>;

  // dtheta_variance: the variance of the input, dead-reckoned (Sec. 3.10: an offset plus a
  // fraction of the increment, squared) or, without dead reckoning, the turn a slot may hold.
  // extra_position_variance_m2: added on x and y, for a robot that moved by an unknown direction
  // (its heading not yet found: KleemanIekf carries it at v = 0 and this variance).
  SlotTransition(double dtheta_variance_rad2, const SlotNoise& noise, double extra_position_variance_m2 = 0.0)
      : dtheta_variance_rad2_(dtheta_variance_rad2), noise_(noise), extra_position_variance_m2_(extra_position_variance_m2) {}

  template <int N>
  Vec<N> step(const Vec<N>& x, const Input& u, double /*dt_s*/) const {
    return linearize(x, u, 0.0).step;
  }
  template <int N>
  MotionLinearization<N, 1> linearize(const Vec<N>& x, const Input& u, double /*dt_s*/) const {
    static_assert(N == kStateSize, "seed 002's state (eq. 14)");
    const double v = x(kSpeed), period = x(kCycle), heading = x(kHeading) + 0.5 * u(0);
    const double c = std::cos(heading), s = std::sin(heading);
    MotionLinearization<N, 1> m;
    m.step.setZero();
    m.step(kX) = v * period * c;  // eq. 15
    m.step(kY) = v * period * s;
    m.step(kHeading) = u(0);        // eq. 24
    m.step(kFireTime) = period;     // t0(k+1) = t0(k) + T(k)
    m.jacobian_state.setIdentity();  // eq. 16
    m.jacobian_state(kX, kSpeed) = period * c;
    m.jacobian_state(kX, kHeading) = -period * v * s;
    m.jacobian_state(kX, kCycle) = v * c;
    m.jacobian_state(kY, kSpeed) = period * s;
    m.jacobian_state(kY, kHeading) = period * v * c;
    m.jacobian_state(kY, kCycle) = v * s;
    m.jacobian_state(kFireTime, kCycle) = 1.0;
    m.jacobian_input.setZero();
    m.jacobian_input(kX, 0) = -0.5 * period * v * s;
    m.jacobian_input(kY, 0) = 0.5 * period * v * c;
    m.jacobian_input(kHeading, 0) = 1.0;
    return m;
  }
  Mat<1, 1> input_noise(const Input& /*u*/) const { return Mat<1, 1>(dtheta_variance_rad2_); }
  template <int N>
  Mat<N, N> state_noise(Eigen::Index /*n*/, double /*dt_s*/) const {
    Vec<N> sigma = Vec<N>::Zero();
    sigma(kX) = sigma(kY) = noise_.position_m;
    sigma(kSpeed) = noise_.speed_mps;
    sigma(kCycle) = noise_.cycle_s;
    sigma(kFireTime) = noise_.fire_time_s;
    sigma(kSpeedOfSound) = noise_.speed_of_sound_mps;
    Vec<N> variance = sigma.cwiseProduct(sigma);
    variance(kX) += extra_position_variance_m2_;
    variance(kY) += extra_position_variance_m2_;
    return variance.asDiagonal();
  }

 private:
  double dtheta_variance_rad2_;
  SlotNoise noise_;
  double extra_position_variance_m2_;
};

}  // namespace beaconloc::kleeman
