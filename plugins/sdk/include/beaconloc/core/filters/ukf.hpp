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
//  - One iteration of seed 001 Table 1 draws ONE set of sigma points over [x; w_u; v] for both:
//    predict(motion, u, dt, R) moves them and keeps them (SigmaPoints), the caller may look at the
//    moved points (seed 001 Table 2 associates beacons over them), and update(points, model, z)
//    corrects with the same points. sigma_points(R) draws such a set without a motion.
//  - A ComponentGate leaves the components of a vector measurement that are gross outliers on
//    their own (|nu_i| > g sqrt(S_ii)) out of the update, and fuses the rest.
// Sizes of the augmented sets are known at run time only: dynamic Eigen types inside.
#include <Eigen/Cholesky>
#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <utility>
#include <vector>

#include "beaconloc/core/filters/gaussian_filter.hpp"
#include "beaconloc/core/filters/unscented.hpp"

namespace beaconloc {

struct UkfOptions {
  UnscentedParameters unscented;
  bool augment_measurement_noise = false;
};

// Components [first, first + count) of a measurement whose innovation is more than `sigmas`
// times their own predicted standard deviation (|nu_i| > sigmas sqrt(S_ii)) are left out of the
// update one by one: the others are fused as if those had not been measured (their rows and
// columns of S and P_xz dropped, which is exact). For a vector of independent readings of which
// a few may be gross outliers (laser beams that met what the map does not have). The default,
// or a gate that is not a positive number, leaves every component in.
struct ComponentGate {
  Eigen::Index first = 0;
  Eigen::Index count = 0;
  double sigmas = std::numeric_limits<double>::infinity();
};

template <int N>
class Ukf;

// The sigma points of one iteration of the UKF, drawn by Ukf::predict(motion, u, dt, R) or
// Ukf::sigma_points(R): valid for the belief they were drawn at and the noise R they spread.
template <int N>
class SigmaPoints {
 public:
  // The points' states (n x (2L + 1)), moved by the motion when there was one.
  const Eigen::MatrixXd& states() const { return states_; }
  const UnscentedWeights& weights() const { return weights_; }

 private:
  friend class Ukf<N>;
  explicit SigmaPoints(UnscentedWeights weights) : weights_(std::move(weights)) {}
  UnscentedWeights weights_;
  Eigen::MatrixXd states_;
  Eigen::MatrixXd deviations_;  // each state (-) mean_: eq. 13's deviations, which eq. 20 uses again
  // The augmented points as drawn ([x; w_u; v] x (2L + 1)): their last measurement_rows_ rows are
  // each point's measurement noise, the augmented part of seed 001 eq. 8 (chi_n); none when R
  // is added to S instead. Kept whole, not copied out.
  Eigen::MatrixXd augmented_;
  Eigen::Index measurement_rows_ = 0;
  Eigen::MatrixXd r_;  // the R they spread (augmented) or are to add
  Vec<N> mean_;        // the belief they spread: the filter's when they were drawn
  Mat<N, N> covariance_;
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
    return predict(motion, u, dt_s, Eigen::MatrixXd(0, 0)).result;
  }

  struct Predicted {
    PredictResult result;
    std::optional<SigmaPoints<N>> points;  // when applied
  };
  // Seed 001 Table 1: sigma points of [x; w_u; v] (eq. 1-8), v ~ N(0, measurement_noise) the
  // noise of the correction to follow (0 x 0: none), each moved x (+) dx(x, u + w_u) (eq. 9-11);
  // the prior (eq. 12-13) replaces the belief, and the moved points are kept for that correction.
  // A motion with additive state noise Q has its points drawn again from the prior (Q in it), as
  // a moved set does not spread Q (no points, the prediction applied, when that draw fails).
  template <class Motion>
  Predicted predict(const Motion& motion, const typename Motion::Input& u, double dt_s,
                    Eigen::MatrixXd measurement_noise) {
    const Eigen::Index n = this->x_.size();
    const Eigen::Index n_u = Motion::kInputSize;
    const Eigen::MatrixXd input_noise = motion.input_noise(u);
    if (!input_noise.allFinite() || !u.allFinite() || !measurement_noise.allFinite()) {
      return {{FilterOutcome::kNonFinite}, std::nullopt};
    }
    // With state noise the points are drawn again from the prior below: these spread no
    // measurement noise.
    std::optional<SigmaPoints<N>> points;
    if constexpr (Motion::kHasStateNoise) {
      points = draw(input_noise, Eigen::MatrixXd(0, 0));
    } else {
      points = draw(input_noise, std::move(measurement_noise));
    }
    if (!points) return {{FilterOutcome::kNotPositiveDefinite}, std::nullopt};
    const Eigen::MatrixXd& chi = points->augmented_;
    Eigen::MatrixXd moved(n, chi.cols());
    for (Eigen::Index i = 0; i < chi.cols(); ++i) {
      // A point that spreads only measurement noise moves as the first: no second motion step.
      if (i > 0 && chi.col(i).head(n + n_u) == chi.col(0).head(n + n_u)) {
        moved.col(i) = moved.col(0);
        continue;
      }
      const State xi = chi.col(i).head(n);
      const typename Motion::Input ui = u + chi.col(i).segment(n, n_u);
      moved.col(i) = this->space_.plus(xi, motion.step(xi, ui, dt_s));
    }
    if (!moved.allFinite()) return {{FilterOutcome::kNonFinite}, std::nullopt};
    State mean;
    Eigen::MatrixXd centred;
    state_moments(moved, points->weights_, mean, centred);
    Covariance p = weighted_covariance(centred, points->weights_);
    if constexpr (Motion::kHasStateNoise) p += motion.template state_noise<N>(n, dt_s);
    if (!p.allFinite()) return {{FilterOutcome::kNonFinite}, std::nullopt};
    this->x_ = mean;
    this->p_ = symmetrized(p);
    if constexpr (Motion::kHasStateNoise) {
      points = sigma_points(std::move(measurement_noise));
      if (!points) return {{FilterOutcome::kApplied}, std::nullopt};  // predicted; no correction possible
    } else {
      points->states_ = std::move(moved);
      points->deviations_ = std::move(centred);
      points->mean_ = this->x_;
      points->covariance_ = this->p_;
    }
    return {{}, std::move(points)};
  }

  // Sigma points of the belief as it is, for a correction whose noise R = measurement_noise is
  // augmented (seed 001 eq. 16); nullopt when the augmented covariance is not positive definite.
  std::optional<SigmaPoints<N>> sigma_points(Eigen::MatrixXd measurement_noise) const {
    if (!measurement_noise.allFinite()) return std::nullopt;
    return draw(Eigen::MatrixXd(0, 0), std::move(measurement_noise));
  }

  template <class Model>
  UpdateResult update(const Model& model, const typename Model::Vector& z,
                      double nis_gate = std::numeric_limits<double>::infinity(), ComponentGate gate = {}) {
    const Eigen::MatrixXd r = model.noise();
    UpdateResult result;
    result.iterations = 1;
    result.outcome = this->check_measurement(model, z, r);
    if (!result.applied()) return result;
    std::optional<SigmaPoints<N>> points = options_.augment_measurement_noise ? sigma_points(r) : draw_additive(r);
    if (!points) {
      result.outcome = FilterOutcome::kNotPositiveDefinite;
      return result;
    }
    return correct(*points, model, z, r, nis_gate, gate);
  }

  // Seed 001 eq. 15-22 over points drawn for this belief: z_i = h(x_i) (+ v_i, eq. 16), their
  // mean and S (eq. 18-19, + R when not augmented), P_xz (eq. 20), K = P_xz S^-1, the posterior
  // (eq. 21-22). kStaleSigmaPoints when the belief or R is not the one they were drawn for.
  template <class Model>
  UpdateResult update(const SigmaPoints<N>& points, const Model& model, const typename Model::Vector& z,
                      double nis_gate = std::numeric_limits<double>::infinity(), ComponentGate gate = {}) {
    UpdateResult result;
    result.iterations = 1;
    const Eigen::MatrixXd r = model.noise();
    result.outcome = this->check_measurement(model, z, r);
    if (!result.applied()) return result;
    if (!same(points.mean_, this->x_) || !same(points.covariance_, this->p_) || !same(points.r_, r)) {
      result.outcome = FilterOutcome::kStaleSigmaPoints;
      return result;
    }
    return correct(points, model, z, r, nis_gate, gate);
  }

 private:
  // The correction of update(points, model, z) once z and R = r are checked and the points are
  // this belief's, drawn for r.
  template <class Model>
  UpdateResult correct(const SigmaPoints<N>& points, const Model& model, const typename Model::Vector& z,
                       const Eigen::MatrixXd& r, double nis_gate, ComponentGate gate) {
    UpdateResult result;
    result.iterations = 1;
    const Eigen::Index m = model.size();
    const Eigen::MatrixXd& states = points.states_;
    const UnscentedWeights& w = points.weights_;
    const bool augmented = points.measurement_rows_ > 0;
    const Eigen::Index count = states.cols();
    Eigen::MatrixXd z_sigma(m, count);
    for (Eigen::Index i = 0; i < count; ++i) {
      // A point that spreads only measurement noise keeps the first's state: its h is the first
      // point's (exact, and no second ray cast or solve).
      if (i > 0 && states.col(i) == states.col(0)) {
        z_sigma.col(i) = z_sigma.col(0);
      } else {
        predict_into(model, State(states.col(i)), z_sigma.col(i));
      }
    }
    if (!z_sigma.allFinite()) {
      result.outcome = FilterOutcome::kNonFinite;
      return result;
    }
    if (augmented) z_sigma += points.augmented_.bottomRows(points.measurement_rows_);  // eq. 16: + chi_n
    typename Model::Vector z_mean;
    Eigen::MatrixXd z_centred(m, count);
    if constexpr (plain_residual_v<Model>) {
      z_mean = weighted_mean(z_sigma, w);  // eq. 18
      z_centred = z_sigma.colwise() - Eigen::VectorXd(z_mean);
    } else {
      // The mean as offsets from the first point (angle-aware through the residual).
      const typename Model::Vector z0 = z_sigma.col(0);
      Eigen::MatrixXd z_offsets(m, count);
      for (Eigen::Index i = 0; i < count; ++i) {
        z_offsets.col(i) = model.residual(typename Model::Vector(z_sigma.col(i)), z0);
      }
      z_mean = z0 + typename Model::Vector(weighted_mean(z_offsets, w));
      for (Eigen::Index i = 0; i < count; ++i) {
        z_centred.col(i) = model.residual(typename Model::Vector(z_sigma.col(i)), z_mean);
      }
    }
    Eigen::MatrixXd s = weighted_covariance(z_centred, w);  // eq. 19
    if (!augmented) s += r;
    Eigen::MatrixXd xz = weighted_cross_covariance(points.deviations_, z_centred, w);  // eq. 20
    Eigen::VectorXd innovation = model.residual(z, z_mean);
    if (!leave_out_gated(gate, innovation, s, xz, result.components_gated)) {
      result.outcome = FilterOutcome::kEveryComponentGated;
      return result;
    }
    const InnovationFactor<Eigen::Dynamic> factor(s);
    if (!factor.ok()) {
      result.outcome = FilterOutcome::kSingularInnovation;
      return result;
    }
    result.nis = factor.nis(innovation);
    result.log_det_s = factor.log_det();
    if (!(result.nis <= nis_gate)) {
      result.outcome = FilterOutcome::kGated;
      return result;
    }
    // K = P_xz S^-1, and K S K^T = P_xz S^-1 P_xz^T = P_xz K^T: one product fewer.
    const Eigen::MatrixXd k_transposed = factor.solve(xz.transpose());
    const Covariance p = symmetrized(Covariance(this->p_ - xz * k_transposed));
    if (Eigen::LLT<Covariance>(p).info() != Eigen::Success) {
      result.outcome = FilterOutcome::kNotPositiveDefinite;
      return result;
    }
    this->x_ = this->space_.plus(this->x_, State(k_transposed.transpose() * innovation));
    this->p_ = p;
    return result;
  }

  // ComponentGate: drops the gated components' rows of the innovation, rows and columns of S and
  // columns of P_xz, counting them; false when nothing is left to fuse.
  static bool leave_out_gated(const ComponentGate& gate, Eigen::VectorXd& innovation, Eigen::MatrixXd& s,
                              Eigen::MatrixXd& xz, int& gated) {
    if (!(gate.sigmas > 0.0) || std::isinf(gate.sigmas)) return true;  // no gate (NaN and inf gate nothing)
    const Eigen::Index m = innovation.size();
    const Eigen::Index first = std::clamp<Eigen::Index>(gate.first, 0, m);
    const Eigen::Index last = first + std::clamp<Eigen::Index>(gate.count, 0, m - first);
    const double limit = gate.sigmas * gate.sigmas;
    const auto gated_out = [&](Eigen::Index i) {
      return i >= first && i < last && !(innovation(i) * innovation(i) <= limit * s(i, i));
    };
    Eigen::Index dropped = 0;
    for (Eigen::Index i = 0; i < m; ++i) dropped += gated_out(i) ? 1 : 0;
    gated += static_cast<int>(dropped);
    if (dropped == 0) return true;  // the common case: nothing to copy
    if (dropped == m) return false;
    std::vector<Eigen::Index> kept;
    kept.reserve(static_cast<std::size_t>(m - dropped));
    for (Eigen::Index i = 0; i < m; ++i) {
      if (!gated_out(i)) kept.push_back(i);
    }
    innovation = Eigen::VectorXd(innovation(kept));
    s = Eigen::MatrixXd(s(kept, kept));
    xz = Eigen::MatrixXd(xz(Eigen::all, kept));
    return true;
  }
  template <class A, class B>
  static bool same(const Eigen::MatrixBase<A>& a, const Eigen::MatrixBase<B>& b) {
    return a.rows() == b.rows() && a.cols() == b.cols() && a == b;
  }
  // The transform needs L + lambda = alpha^2 (L + kappa) > 0.
  bool defined_for(Eigen::Index l) const {
    const UnscentedParameters& p = options_.unscented;
    return l >= 1 && p.alpha * p.alpha * (static_cast<double>(l) + p.kappa) > 0.0;
  }
  // Sigma points (eq. 2) of the belief augmented with zero-mean noises (eq. 4-5, 7): the input's
  // and the measurement's, block-diagonal; the augmented points kept whole, for predict to
  // move (the measurement's rows last). nullopt when not positive definite.
  std::optional<SigmaPoints<N>> draw(const Eigen::MatrixXd& input_noise, Eigen::MatrixXd measurement_noise) const {
    const Eigen::Index n = this->x_.size(), n_u = input_noise.rows(), m = measurement_noise.rows();
    const Eigen::Index l = n + n_u + m;
    if (!defined_for(l)) return std::nullopt;
    Eigen::VectorXd mean_a = Eigen::VectorXd::Zero(l);
    mean_a.head(n) = this->x_;
    Eigen::MatrixXd cov_a = Eigen::MatrixXd::Zero(l, l);
    cov_a.topLeftCorner(n, n) = this->p_;
    if (n_u > 0) cov_a.block(n, n, n_u, n_u) = input_noise;
    if (m > 0) cov_a.bottomRightCorner(m, m) = measurement_noise;
    SigmaPoints<N> points{UnscentedWeights(l, options_.unscented)};
    std::optional<Eigen::MatrixXd> chi = beaconloc::sigma_points(mean_a, cov_a, points.weights_);
    if (!chi) return std::nullopt;
    points.augmented_ = std::move(*chi);
    points.measurement_rows_ = m;
    if (n_u == 0) {  // no motion to move them
      points.states_ = points.augmented_.topRows(n);
      points.deviations_.resize(n, points.states_.cols());
      for (Eigen::Index i = 0; i < points.states_.cols(); ++i) {
        points.deviations_.col(i) = this->space_.minus(State(points.states_.col(i)), this->x_);
      }
    }
    points.r_ = std::move(measurement_noise);
    points.mean_ = this->x_;
    points.covariance_ = this->p_;
    return points;
  }
  // Sigma points of the belief alone, R to be added to S.
  std::optional<SigmaPoints<N>> draw_additive(const Eigen::MatrixXd& r) const {
    std::optional<SigmaPoints<N>> points = draw(Eigen::MatrixXd(0, 0), Eigen::MatrixXd(0, 0));
    if (points) points->r_ = r;
    return points;
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
