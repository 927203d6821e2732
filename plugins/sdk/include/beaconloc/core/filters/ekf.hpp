#pragma once
// Extended Kalman filter on a fixed-size state. The filter knows no model: the caller
// linearizes its motion and measurement models (kept apart in core/models) and passes the
// Jacobians, so the same models serve the EKF, IEKF, UKF and H-infinity filters.
#include <Eigen/Cholesky>
#include <Eigen/Core>

#include "beaconloc/core/filters/symmetric.hpp"

namespace beaconloc {

enum class UpdateOutcome {
  kApplied,
  kGated,               // NIS above the gate: the measurement is an outlier for this state
  kSingularInnovation,  // S not positive definite: nothing applied
};

struct UpdateResult {
  UpdateOutcome outcome = UpdateOutcome::kApplied;
  double nis = 0.0;  // normalized innovation squared nu^T S^-1 nu
};

template <int N>
class Ekf {
 public:
  using State = Eigen::Matrix<double, N, 1>;
  using Covariance = Eigen::Matrix<double, N, N>;

  void reset(const State& x, const Covariance& p) {
    x_ = x;
    p_ = p;
  }
  const State& state() const { return x_; }
  const Covariance& covariance() const { return p_; }
  State& mutable_state() { return x_; }

  // P = F P F^T + Q with x already propagated by the motion model.
  void predict(const State& x_predicted, const Covariance& f, const Covariance& q) {
    x_ = x_predicted;
    p_ = f * p_ * f.transpose() + q;
    p_ = symmetrized(p_);
  }

  // innovation = z - h(x) (angle components wrapped by the caller), Jacobian H, noise R.
  // Gain from an LDLT solve of S (checked), Joseph-form covariance update.
  template <int M>
  UpdateResult update(const Eigen::Matrix<double, M, 1>& innovation, const Eigen::Matrix<double, M, N>& h,
                      const Eigen::Matrix<double, M, M>& r, double nis_gate) {
    UpdateResult result;
    const Eigen::Matrix<double, M, M> s = h * p_ * h.transpose() + r;
    const Eigen::LDLT<Eigen::Matrix<double, M, M>> ldlt(s);
    if (ldlt.info() != Eigen::Success || !ldlt.isPositive() || (ldlt.vectorD().array() <= 0.0).any()) {
      result.outcome = UpdateOutcome::kSingularInnovation;
      return result;
    }
    result.nis = innovation.dot(ldlt.solve(innovation));
    if (!(result.nis <= nis_gate)) {
      result.outcome = UpdateOutcome::kGated;
      return result;
    }
    // K = P H^T S^-1, computed as (S^-1 H P)^T since S and P are symmetric.
    const Eigen::Matrix<double, N, M> k = ldlt.solve(h * p_).transpose();
    x_ += k * innovation;
    const Covariance i_kh = Covariance::Identity() - k * h;
    p_ = i_kh * p_ * i_kh.transpose() + k * r * k.transpose();
    p_ = symmetrized(p_);
    return result;
  }

 private:
  State x_ = State::Zero();
  Covariance p_ = Covariance::Identity();
};

}  // namespace beaconloc
