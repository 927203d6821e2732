#pragma once
// Extended Kalman filter over models (core/models/model_concepts.hpp): predict(motion, u, dt)
// and update(model, z). The gain comes from a checked LDLT of the innovation covariance, the
// covariance update is in Joseph form, and the correction is composed in the state space, which
// wraps the headings (state_space.hpp).
#include <limits>

#include "beaconloc/core/filters/gaussian_filter.hpp"

namespace beaconloc {

template <int N>
class Ekf : public LinearizedFilter<N> {
 public:
  using typename LinearizedFilter<N>::Space;
  using typename LinearizedFilter<N>::State;
  using typename LinearizedFilter<N>::Covariance;
  explicit Ekf(Space space = Space()) : LinearizedFilter<N>(space) {}

  // nu = z (-) h(x), S = H P H^T + R, K = P H^T S^-1, x = x (+) K nu,
  // P = (I - K H) P (I - K H)^T + K R K^T. Not applied when nu^T S^-1 nu > nis_gate (kGated),
  // S is not positive definite, or the model's numbers are not finite.
  template <class Model>
  UpdateResult update(const Model& model, const typename Model::Vector& z,
                      double nis_gate = std::numeric_limits<double>::infinity()) {
    static_assert(Model::kHasJacobian, "the EKF linearizes its measurement model: this model has no Jacobian");
    constexpr int M = Model::kSize;
    UpdateResult result;
    result.iterations = 1;
    if (const FilterOutcome checked = this->check_measurement(model, z); checked != FilterOutcome::kApplied) {
      result.outcome = checked;
      return result;
    }
    const MeasurementLinearization<M, N> lin = model.linearize(this->x_);
    const Mat<M, M> r = model.noise();
    if (!lin.predicted.allFinite() || !lin.jacobian.allFinite() || !r.allFinite()) {
      result.outcome = FilterOutcome::kNonFinite;
      return result;
    }
    const Vec<M> innovation = model.residual(z, lin.predicted);
    const Mat<M, N>& h = lin.jacobian;
    const InnovationFactor<M> s(h * this->p_ * h.transpose() + r);
    if (!s.ok) {
      result.outcome = FilterOutcome::kSingularInnovation;
      return result;
    }
    result.nis = innovation.dot(s.ldlt.solve(innovation));
    if (!(result.nis <= nis_gate)) {
      result.outcome = FilterOutcome::kGated;
      return result;
    }
    // K = P H^T S^-1, computed as (S^-1 H P)^T since S and P are symmetric.
    const Mat<N, M> k = s.ldlt.solve(h * this->p_).transpose();
    this->x_ = this->space_.plus(this->x_, k * innovation);
    const Covariance i_kh = Covariance::Identity(this->x_.size(), this->x_.size()) - k * h;
    this->p_ = i_kh * this->p_ * i_kh.transpose() + k * r * k.transpose();
    this->p_ = symmetrized(this->p_);
    return result;
  }
};

}  // namespace beaconloc
