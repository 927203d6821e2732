#pragma once
// Unscented Kalman filter over models (core/models/model_concepts.hpp), on the scaled unscented
// transform of unscented.hpp (seed 001 eq. 2, 12-14; seed 003 eq. 14-33): no Jacobian is needed,
// so it also takes the models that have none (the laser beams).
//  - predict(motion, u, dt): sigma points of the state augmented with the input noise U(u)
//    (seed 001 eq. 1-8: the motion's noise enters through the model), each moved x (+) dx(x, u + w);
//    the mean of the moved points is taken as offsets from the first (state_space.hpp), so
//    headings average across +-pi.
//  - update(model, z): the measurement's noise additive (S = sum w (z_i - z)(z_i - z)^T + R), or
//    augmented as seed 001 eq. 16 does (UkfOptions::augment_measurement_noise: sigma points over
//    [x; v], z_i = h(x_i) + v_i). The gain from a checked LDLT of S (seed 003 ERRATA: K = P_xz
//    S^-1), P = P - K S K^T checked positive definite: otherwise nothing changes.
// Sizes of the augmented sets are known at run time only: dynamic Eigen types inside.
#include <Eigen/Cholesky>
#include <cmath>
#include <limits>

#include "beaconloc/core/filters/gaussian_filter.hpp"
#include "beaconloc/core/filters/unscented.hpp"

namespace beaconloc {

struct UkfOptions {
  UnscentedParameters unscented;
  bool augment_measurement_noise = false;
};

template <int N>
class Ukf : public GaussianFilter<N> {
 public:
  using typename GaussianFilter<N>::Space;
  using typename GaussianFilter<N>::State;
  using typename GaussianFilter<N>::Covariance;
  explicit Ukf(Space space = Space(), UkfOptions options = {}) : GaussianFilter<N>(space), options_(options) {}
  const UkfOptions& options() const { return options_; }

  template <class Motion>
  PredictResult predict(const Motion& motion, const typename Motion::Input& u, double dt_s) {
    const Eigen::Index n = this->x_.size();
    const Eigen::Index n_u = Motion::kInputSize;
    const Eigen::MatrixXd input_noise = motion.input_noise(u);
    if (!input_noise.allFinite() || !u.allFinite()) return {FilterOutcome::kNonFinite};
    const Eigen::Index l = n + n_u;
    if (!defined_for(l)) return {FilterOutcome::kNotPositiveDefinite};
    Eigen::VectorXd mean_a = Eigen::VectorXd::Zero(l);
    mean_a.head(n) = this->x_;
    Eigen::MatrixXd cov_a = Eigen::MatrixXd::Zero(l, l);
    cov_a.topLeftCorner(n, n) = this->p_;
    cov_a.bottomRightCorner(n_u, n_u) = input_noise;
    const UnscentedWeights w(l, options_.unscented);
    const auto chi = sigma_points(mean_a, cov_a, w);
    if (!chi) return {FilterOutcome::kNotPositiveDefinite};
    Eigen::MatrixXd moved(n, chi->cols());
    for (Eigen::Index i = 0; i < chi->cols(); ++i) {
      const State xi = chi->col(i).head(n);
      const typename Motion::Input ui = u + chi->col(i).tail(n_u);
      moved.col(i) = this->space_.plus(xi, motion.step(xi, ui, dt_s));
    }
    if (!moved.allFinite()) return {FilterOutcome::kNonFinite};
    State mean;
    Eigen::MatrixXd centred;
    state_moments(moved, w, mean, centred);
    Covariance p = weighted_cross_covariance(centred, centred, w);
    if constexpr (Motion::kHasStateNoise) p += motion.template state_noise<N>(n, dt_s);
    if (!p.allFinite()) return {FilterOutcome::kNonFinite};
    this->x_ = mean;
    this->p_ = symmetrized(p);
    return {};
  }

  template <class Model>
  UpdateResult update(const Model& model, const typename Model::Vector& z,
                      double nis_gate = std::numeric_limits<double>::infinity()) {
    UpdateResult result;
    result.iterations = 1;
    const Eigen::MatrixXd r = model.noise();
    result.outcome = this->check_measurement(model, z, r);
    if (!result.applied()) return result;
    const Eigen::Index n = this->x_.size(), m = model.size();
    const bool augmented = options_.augment_measurement_noise;
    const Eigen::Index l = augmented ? n + m : n;
    if (!defined_for(l)) {
      result.outcome = FilterOutcome::kNotPositiveDefinite;
      return result;
    }
    Eigen::VectorXd mean_a = Eigen::VectorXd::Zero(l);
    mean_a.head(n) = this->x_;
    Eigen::MatrixXd cov_a = Eigen::MatrixXd::Zero(l, l);
    cov_a.topLeftCorner(n, n) = this->p_;
    if (augmented) cov_a.bottomRightCorner(m, m) = r;
    const UnscentedWeights w(l, options_.unscented);
    const auto chi = sigma_points(mean_a, cov_a, w);
    if (!chi) {
      result.outcome = FilterOutcome::kNotPositiveDefinite;
      return result;
    }
    const Eigen::Index count = chi->cols();
    Eigen::MatrixXd z_sigma(m, count);
    for (Eigen::Index i = 0; i < count; ++i) {
      // A point that spreads only measurement noise keeps the mean's state: its h is the first
      // point's (exact, and no second ray cast or solve).
      if (i > 0 && chi->col(i).head(n) == chi->col(0).head(n)) {
        z_sigma.col(i) = z_sigma.col(0);
      } else {
        const State xi = chi->col(i).head(n);
        z_sigma.col(i) = model.predict(xi);
      }
    }
    if (!z_sigma.allFinite()) {
      result.outcome = FilterOutcome::kNonFinite;
      return result;
    }
    if (augmented) z_sigma += chi->bottomRows(m);  // seed 001 eq. 16: + chi_n
    // The measurement's mean as offsets from the first point (angle-aware through the residual).
    const typename Model::Vector z0 = z_sigma.col(0);
    Eigen::MatrixXd z_offsets(m, count);
    for (Eigen::Index i = 0; i < count; ++i) {
      z_offsets.col(i) = model.residual(typename Model::Vector(z_sigma.col(i)), z0);
    }
    const typename Model::Vector z_mean = z0 + typename Model::Vector(weighted_mean(z_offsets, w));
    Eigen::MatrixXd z_centred(m, count);
    for (Eigen::Index i = 0; i < count; ++i) {
      z_centred.col(i) = model.residual(typename Model::Vector(z_sigma.col(i)), z_mean);
    }
    Eigen::MatrixXd x_centred(n, count);
    for (Eigen::Index i = 0; i < count; ++i) {
      x_centred.col(i) = this->space_.minus(State(chi->col(i).head(n)), this->x_);
    }
    Eigen::MatrixXd s = weighted_cross_covariance(z_centred, z_centred, w);
    if (!augmented) s += r;
    const Eigen::MatrixXd xz = weighted_cross_covariance(x_centred, z_centred, w);
    const InnovationFactor<Eigen::Dynamic> factor(s);
    if (!factor.ok()) {
      result.outcome = FilterOutcome::kSingularInnovation;
      return result;
    }
    const Eigen::VectorXd innovation = model.residual(z, z_mean);
    result.nis = factor.nis(innovation);
    if (!(result.nis <= nis_gate)) {
      result.outcome = FilterOutcome::kGated;
      return result;
    }
    const Eigen::MatrixXd k = factor.solve(xz.transpose()).transpose();
    const Covariance p = symmetrized(Covariance(this->p_ - k * s * k.transpose()));
    if (Eigen::LLT<Covariance>(p).info() != Eigen::Success) {
      result.outcome = FilterOutcome::kNotPositiveDefinite;
      return result;
    }
    this->x_ = this->space_.plus(this->x_, State(k * innovation));
    this->p_ = p;
    return result;
  }

 private:
  // The transform needs L + lambda = alpha^2 (L + kappa) > 0.
  bool defined_for(Eigen::Index l) const {
    const UnscentedParameters& p = options_.unscented;
    return l >= 1 && p.alpha * p.alpha * (static_cast<double>(l) + p.kappa) > 0.0;
  }
  // The weighted mean of the columns as offsets from the first (so headings average across
  // +-pi), and the columns centred on it.
  void state_moments(const Eigen::MatrixXd& points, const UnscentedWeights& w, State& mean,
                     Eigen::MatrixXd& centred) const {
    const State ref = points.col(0);
    Eigen::MatrixXd offsets(points.rows(), points.cols());
    for (Eigen::Index i = 0; i < points.cols(); ++i) offsets.col(i) = this->space_.minus(State(points.col(i)), ref);
    mean = this->space_.plus(ref, State(weighted_mean(offsets, w)));
    centred.resize(points.rows(), points.cols());
    for (Eigen::Index i = 0; i < points.cols(); ++i) centred.col(i) = this->space_.minus(State(points.col(i)), mean);
  }

  UkfOptions options_;
};

}  // namespace beaconloc
