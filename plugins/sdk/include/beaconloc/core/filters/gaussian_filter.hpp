#pragma once
// What every filter of core/filters holds: a Gaussian belief (mean x, covariance P) on a state
// space (state_space.hpp), and the linearized prediction the EKF, iterated EKF and H-infinity
// filters share: x = x (+) dx(x, u), P = F P F^T + G U G^T (+ Q) (core/models/model_concepts.hpp).
#include <Eigen/Cholesky>

#include "beaconloc/core/filters/outcome.hpp"
#include "beaconloc/core/filters/state_space.hpp"
#include "beaconloc/core/filters/symmetric.hpp"
#include "beaconloc/core/models/model_concepts.hpp"

namespace beaconloc {

template <int N>
class GaussianFilter {
 public:
  using Space = StateSpace<N>;
  using State = Vec<N>;
  using Covariance = Mat<N, N>;

  explicit GaussianFilter(Space space = Space()) : space_(space) {
    x_ = State::Zero(space_.dimension());
    p_ = Covariance::Identity(space_.dimension(), space_.dimension());
  }

  // Start from this belief (headings outside (-pi, pi] wrapped). Refused (kSizeMismatch, kNonFinite; nothing changed) when x or P
  // does not have the space's size or is not finite; P is the caller's (a singular P shows as
  // a singular innovation at the next update).
  FilterOutcome reset(const State& x, const Covariance& p) {
    if (x.size() != space_.dimension() || p.rows() != space_.dimension() || p.cols() != space_.dimension()) {
      return FilterOutcome::kSizeMismatch;
    }
    if (!x.allFinite() || !p.allFinite()) return FilterOutcome::kNonFinite;
    x_ = x;
    space_.normalize(x_);
    p_ = p;
    return FilterOutcome::kApplied;
  }
  const State& state() const { return x_; }
  const Covariance& covariance() const { return p_; }
  const Space& space() const { return space_; }

 protected:
  // Every check of a measurement against the model and the state: sizes and finite numbers.
  template <class Model>
  FilterOutcome check_measurement(const Model& model, const typename Model::Vector& z) const {
    if (z.size() != model.size()) return FilterOutcome::kSizeMismatch;
    if (!z.allFinite()) return FilterOutcome::kNonFinite;
    return FilterOutcome::kApplied;
  }

  Space space_;
  State x_;
  Covariance p_;
};

// The prediction of the filters that linearize (EKF, iterated EKF, H-infinity).
template <int N>
class LinearizedFilter : public GaussianFilter<N> {
 public:
  using typename GaussianFilter<N>::Space;
  using typename GaussianFilter<N>::State;
  using typename GaussianFilter<N>::Covariance;
  explicit LinearizedFilter(Space space = Space()) : GaussianFilter<N>(space) {}

  // x = x (+) dx, P = F P F^T + G U G^T (+ Q). Not applied (kNonFinite) when the model's step,
  // Jacobians or noise are not finite.
  template <class Motion>
  PredictResult predict(const Motion& motion, const typename Motion::Input& u, double dt_s) {
    const MotionLinearization<N, Motion::kInputSize> m = motion.linearize(this->x_, u, dt_s);
    const Mat<Motion::kInputSize, Motion::kInputSize> input_noise = motion.input_noise(u);
    if (!m.step.allFinite() || !m.jacobian_state.allFinite() || !m.jacobian_input.allFinite() ||
        !input_noise.allFinite()) {
      return {FilterOutcome::kNonFinite};
    }
    Covariance q = m.jacobian_input * input_noise * m.jacobian_input.transpose();
    if constexpr (Motion::kHasStateNoise) {
      q += motion.template state_noise<N>(this->space_.dimension(), dt_s);
      if (!q.allFinite()) return {FilterOutcome::kNonFinite};
    }
    this->x_ = this->space_.plus(this->x_, m.step);
    this->p_ = m.jacobian_state * this->p_ * m.jacobian_state.transpose() + q;
    this->p_ = symmetrized(this->p_);
    return {};
  }
};

// S = H P H^T + R factorized and checked: positive definite, or nothing.
template <int M>
struct InnovationFactor {
  Eigen::LDLT<Mat<M, M>> ldlt;
  bool ok = false;
  explicit InnovationFactor(const Mat<M, M>& s) : ldlt(s) {
    ok = ldlt.info() == Eigen::Success && ldlt.isPositive() && (ldlt.vectorD().array() > 0.0).all();
  }
};

}  // namespace beaconloc
