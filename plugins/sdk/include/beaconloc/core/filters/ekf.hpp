#pragma once
// Extended Kalman filter over models (core/models/model_concepts.hpp): predict(motion, u, dt)
// and update(model, z). The gain comes from a checked factorization of the innovation covariance
// (InnovationFactor: a division for a scalar, an LDLT otherwise), the covariance update is in
// Joseph form, and the correction is composed in the state space, which wraps the headings
// (state_space.hpp).
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
    const auto u = this->linearize_update(model, z);
    result.outcome = u.outcome;
    if (!result.applied()) return result;
    result.nis = u.s->nis(u.innovation);
    result.log_det_s = u.s->log_det();
    if (!(result.nis <= nis_gate)) {
      result.outcome = FilterOutcome::kGated;
      return result;
    }
    const Mat<N, M> k = this->gain(u.h, *u.s);
    this->x_ = this->space_.plus(this->x_, k * u.innovation);
    this->joseph_update(k, u.h, u.r);
    return result;
  }
};

}  // namespace beaconloc
