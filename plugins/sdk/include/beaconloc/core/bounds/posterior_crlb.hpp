#pragma once
// The posterior Cramer-Rao lower bound (PCRB; Tichavsky, Muravchik and Nehorai, "Posterior
// Cramer-Rao bounds for discrete-time nonlinear filtering", IEEE TSP 1998) along a true
// trajectory: a Bayesian (Van Trees) bound, so no estimator of the state from the same data and
// prior can have a smaller mean square error matrix than it (in the positive semi-definite sense),
// on average over the noise and the prior.
//
// For additive Gaussian noises the recursion for the information J_k = P_k^-1 is
//   J_k+1 = (F P_k F^T + G U G^T + Q)^-1 + H^T R^-1 H,
// with F, G and H the models' Jacobians at the TRUE state (not at an estimate). It is the
// EKF's covariance recursion run at the truth, kept here in covariance form (P, not J), so that
// a state with a part known exactly (zero prior variance, never excited) stays well posed.
// Its assumptions, to say beside any figure it prints:
//  - the models are the ones that made the data (the simulator's noise models, their sizes);
//  - every measurement fed is a true one (an echo is not fed: the bound assumes it recognised);
//  - a noise's covariance is taken as given at the true input: where it depends on the state
//    (wheel noise growing with the speed) the information that dependence carries is left out;
//  - it follows one trajectory: the Jacobians are taken at the truth, not averaged over the
//    state's distribution, which is exact for the linear-Gaussian case and the usual
//    approximation elsewhere. So it is a bound on average over many runs; one run's error may
//    fall below it.
// The Kalman filter on a linear-Gaussian model meets it exactly (tests/unit/posterior_crlb_test).
#include "beaconloc/core/filters/gaussian_filter.hpp"

namespace beaconloc {

template <int N>
class PosteriorCrlb {
 public:
  using State = Vec<N>;
  using Covariance = Mat<N, N>;

  // The prior: what is known of the state before any data (a large variance for "nothing").
  explicit PosteriorCrlb(const Covariance& prior) : p_(prior) {}

  // Through one step of the motion with the TRUE input (noise G U G^T (+ Q) from the model's
  // noise at that input), linearized at the true state before the step. kNonFinite (nothing
  // changed) when a number is not finite.
  template <class Motion>
  FilterOutcome predict(const Motion& motion, const State& truth, const typename Motion::Input& u_true, double dt_s) {
    const MotionLinearization<N, Motion::kInputSize> m = motion.linearize(truth, u_true, dt_s);
    Covariance p = m.jacobian_state * p_ * m.jacobian_state.transpose() +
                   m.jacobian_input * motion.input_noise(u_true) * m.jacobian_input.transpose();
    if constexpr (Motion::kHasStateNoise) p += motion.template state_noise<N>(p_.rows(), dt_s);
    if (!p.allFinite()) return FilterOutcome::kNonFinite;
    p_ = symmetrized(p);
    return FilterOutcome::kApplied;
  }

  // One measurement of the model at the TRUE state: P = P - P H^T (H P H^T + R)^-1 H P, in
  // Joseph form (as the filters update). kSingularInnovation when H P H^T + R is not positive
  // definite, kNonFinite when a number is not finite; nothing changed then.
  template <class Model>
  FilterOutcome update(const Model& model, const State& truth) {
    constexpr int M = Model::kSize;
    static_assert(Model::kHasJacobian, "the bound needs the model's Jacobian");
    const MeasurementLinearization<M, N> lin = model.linearize(truth);
    const Mat<M, M> r = model.noise();
    if (!lin.jacobian.allFinite() || !r.allFinite()) return FilterOutcome::kNonFinite;
    const InnovationFactor<M> s(lin.jacobian * p_ * lin.jacobian.transpose() + r);
    if (!s.ok()) return FilterOutcome::kSingularInnovation;
    const Mat<N, M> k = s.solve(lin.jacobian * p_).transpose();
    const Covariance i_kh = Covariance::Identity(p_.rows(), p_.cols()) - k * lin.jacobian;
    const Covariance p = i_kh * p_ * i_kh.transpose() + k * r * k.transpose();
    if (!p.allFinite()) return FilterOutcome::kNonFinite;
    p_ = symmetrized(p);
    return FilterOutcome::kApplied;
  }

  // The bound on the error covariance now.
  const Covariance& covariance() const { return p_; }

 private:
  Covariance p_;
};

}  // namespace beaconloc
