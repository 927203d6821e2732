#pragma once
// H-infinity filter (seed 003 Sec. 3.4.2, eq. 34-38, after Simon, "Optimal State Estimation",
// 2006, Sec. 11.3 with the weights L = S = I): it bounds the worst-case estimation error over
// the noise energy by 1/theta rather than minimizing its variance. The copy's eq. 35 and 38 are
// garbled (ERRATA); the form used is
//   P_up = (P^-1 - theta I + H^T R^-1 H)^-1,   K = P_up H^T R^-1,   x = x (+) K (z (-) h(x)),
// the measurement half of Simon's P_k+1 = F P_k (I - theta P_k + H^T R^-1 H P_k)^-1 F^T + Q
// (the time half is the EKF's prediction, gaussian_filter.hpp). theta = 0 is the EKF (in
// information form); the bound exists only while P^-1 - theta I + H^T R^-1 H is positive definite,
// otherwise the update is refused (kBoundNotMet) and nothing changes.
#include <cmath>
#include <limits>

#include "beaconloc/core/filters/gaussian_filter.hpp"

namespace beaconloc {

template <int N>
class HInfinityFilter : public LinearizedFilter<N> {
 public:
  using typename LinearizedFilter<N>::Space;
  using typename LinearizedFilter<N>::State;
  using typename LinearizedFilter<N>::Covariance;
  // theta >= 0: the performance bound's inverse (seed 003's "attenuation level"); 0 is the EKF.
  explicit HInfinityFilter(Space space = Space(), double theta = 0.0) : LinearizedFilter<N>(space), theta_(theta) {}
  double theta() const { return theta_; }

  // Gated on the NIS of the innovation with S = H P H^T + R, as the EKF is.
  template <class Model>
  UpdateResult update(const Model& model, const typename Model::Vector& z,
                      double nis_gate = std::numeric_limits<double>::infinity()) {
    static_assert(Model::kHasJacobian,
                  "the H-infinity filter linearizes its measurement model: this model has no Jacobian");
    constexpr int M = Model::kSize;
    UpdateResult result;
    result.iterations = 1;
    if (!(theta_ >= 0.0) || !std::isfinite(theta_)) {
      result.outcome = FilterOutcome::kNonFinite;
      return result;
    }
    const auto u = this->linearize_update(model, z);
    result.outcome = u.outcome;
    if (!result.applied()) return result;
    const InnovationFactor<M> r_factor(u.r);
    const Eigen::Index n = this->x_.size();
    const Eigen::LLT<Covariance> p_factor(this->p_);
    if (!r_factor.ok() || p_factor.info() != Eigen::Success) {
      result.outcome = r_factor.ok() ? FilterOutcome::kNotPositiveDefinite : FilterOutcome::kSingularInnovation;
      return result;
    }
    const Mat<M, N>& h = u.h;
    result.nis = u.s->nis(u.innovation);
    result.log_det_s = u.s->log_det();
    if (!(result.nis <= nis_gate)) {
      result.outcome = FilterOutcome::kGated;
      return result;
    }
    const Covariance identity = Covariance::Identity(n, n);
    const Mat<M, N> r_inv_h = r_factor.solve(h);  // R^-1 H
    const Covariance information = p_factor.solve(identity) - theta_ * identity + h.transpose() * r_inv_h;
    const Eigen::LLT<Covariance> bound(symmetrized(information));
    if (bound.info() != Eigen::Success) {
      result.outcome = FilterOutcome::kBoundNotMet;
      return result;
    }
    const Covariance p_up = symmetrized(bound.solve(identity));
    const Mat<N, M> k = p_up * r_inv_h.transpose();  // P_up H^T R^-1
    this->x_ = this->space_.plus(this->x_, k * u.innovation);
    this->p_ = p_up;
    return result;
  }

 private:
  double theta_;
};

}  // namespace beaconloc
