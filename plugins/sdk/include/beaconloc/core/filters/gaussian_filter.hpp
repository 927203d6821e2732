#pragma once
// What every filter of core/filters holds: a Gaussian belief (mean x, covariance P) on a state
// space (state_space.hpp), and the linearized prediction the EKF, iterated EKF and H-infinity
// filters share: x = x (+) dx(x, u), P = F P F^T + G U G^T (+ Q) (core/models/model_concepts.hpp).
#include <Eigen/Cholesky>
#include <cmath>
#include <optional>
#include <type_traits>

#include "beaconloc/core/filters/outcome.hpp"
#include "beaconloc/core/filters/state_space.hpp"
#include "beaconloc/core/filters/symmetric.hpp"
#include "beaconloc/core/models/model_concepts.hpp"

namespace beaconloc {

// S = H P H^T + R factorized and checked: positive definite, or nothing (ok() false). A scalar S
// is its own factorization (a division, checked > 0); a larger one an LDLT, whose pivots are
// checked > 0. The filters solve with S only through solve() and nis().
template <int M>
class InnovationFactor {
 public:
  explicit InnovationFactor(const Mat<M, M>& s) {
    if constexpr (M == 1) {
      factor_ = s(0, 0);
      ok_ = factor_ > 0.0 && std::isfinite(factor_);
    } else {
      factor_.compute(s);
      ok_ = s.allFinite() && factor_.info() == Eigen::Success && factor_.isPositive() &&
            (factor_.vectorD().array() > 0.0).all();
    }
  }
  bool ok() const { return ok_; }
  // S^-1 b
  template <class Rhs>
  Eigen::Matrix<double, M, Rhs::ColsAtCompileTime> solve(const Eigen::MatrixBase<Rhs>& b) const {
    if constexpr (M == 1) {
      return b / factor_;
    } else {
      return factor_.solve(b);
    }
  }
  // The normalized innovation squared nu^T S^-1 nu.
  double nis(const Vec<M>& innovation) const { return innovation.dot(solve(innovation)); }
  // log det S (S checked positive definite: its pivots are > 0).
  double log_det() const {
    if constexpr (M == 1) {
      return std::log(factor_);
    } else {
      return factor_.vectorD().array().log().sum();
    }
  }

 private:
  std::conditional_t<M == 1, double, Eigen::LDLT<Mat<M, M>>> factor_{};  // s itself, or its LDLT
  bool ok_ = false;
};

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
  // Every check of a measurement and its noise R (the model's noise()) before an update: both have
  // the model's size and are finite. kApplied when the update may go on.
  template <class Model, class Noise>
  FilterOutcome check_measurement(const Model& model, const typename Model::Vector& z,
                                  const Eigen::MatrixBase<Noise>& r) const {
    if (z.size() != model.size()) return FilterOutcome::kSizeMismatch;
    if (!z.allFinite()) return FilterOutcome::kNonFinite;
    if (r.rows() != model.size() || r.cols() != model.size()) return FilterOutcome::kSizeMismatch;
    if (!r.allFinite()) return FilterOutcome::kNonFinite;
    return FilterOutcome::kApplied;
  }

  Space space_;
  State x_;
  Covariance p_;
};

// The prediction of the filters that linearize (EKF, iterated EKF, H-infinity).
// LinearizedFilter::prior_innovation.
template <int M>
struct PriorInnovation {
  Vec<M> innovation;
  Mat<M, M> state_covariance;  // H P H^T
};

template <int N>
class LinearizedFilter : public GaussianFilter<N> {
 public:
  using typename GaussianFilter<N>::Space;
  using typename GaussianFilter<N>::State;
  using typename GaussianFilter<N>::Covariance;
  explicit LinearizedFilter(Space space = Space()) : GaussianFilter<N>(space) {}

  // Without updating: the innovation z (-) h(x) at the current state and the share H P H^T of its
  // covariance the state puts there (S less the model's R), for an estimator that decides from
  // them how to fuse z (its weight, its gate). nullopt when z, R, h or H is not usable (update()
  // would refuse it).
  template <class Model>
  std::optional<PriorInnovation<Model::kSize>> prior_innovation(const Model& model,
                                                                const typename Model::Vector& z) const {
    if (this->check_measurement(model, z, model.noise()) != FilterOutcome::kApplied) return std::nullopt;
    PriorInnovation<Model::kSize> out;
    Mat<Model::kSize, N> h;
    if (linearize_at(model, z, this->x_, out.innovation, h) != FilterOutcome::kApplied) return std::nullopt;
    out.state_covariance = h * this->p_ * h.transpose();
    return out;
  }

  // x = x (+) dx, P = F P F^T + G U G^T (+ Q). Not applied (kNonFinite, nothing changed) when
  // the model's step, Jacobians or noise are not finite: checked on the result, which any
  // non-finite number among them makes non-finite (NaN and inf propagate through the products,
  // inf * 0 included), at half the cost of checking each.
  template <class Motion>
  PredictResult predict(const Motion& motion, const typename Motion::Input& u, double dt_s) {
    const MotionLinearization<N, Motion::kInputSize> m = motion.linearize(this->x_, u, dt_s);
    Covariance p = m.jacobian_state * this->p_ * m.jacobian_state.transpose() +
                   m.jacobian_input * motion.input_noise(u) * m.jacobian_input.transpose();
    if constexpr (Motion::kHasStateNoise) p += motion.template state_noise<N>(this->space_.dimension(), dt_s);
    const State x = this->space_.plus(this->x_, m.step);
    if (!x.allFinite() || !p.allFinite()) return {FilterOutcome::kNonFinite};
    this->x_ = x;
    this->p_ = symmetrized(p);
    return {};
  }

 protected:
  // What a linearizing update (EKF, H-infinity) starts from: z and R
  // checked, h and H at the current state, the innovation z (-) h(x), and S = H P H^T + R
  // factorized. outcome says which step failed (kSingularInnovation for S), kApplied if none.
  template <int M>
  // h first: the products read it back as packets as soon as it is written, and behind a lone
  // scalar it straddled two stores, which the CPU cannot forward (a stall per update:
  // BM_Duhl_RangeUpdate took 1.5x as long with r and the innovation first).
  struct LinearizedUpdate {
    FilterOutcome outcome = FilterOutcome::kApplied;
    Mat<M, N> h;
    Vec<M> innovation;
    Mat<M, M> r;
    std::optional<InnovationFactor<M>> s;  // set once h, H and R are good; ok() once outcome is kApplied
  };
  template <class Model>
  LinearizedUpdate<Model::kSize> linearize_update(const Model& model, const typename Model::Vector& z) const {
    LinearizedUpdate<Model::kSize> u;
    u.r = model.noise();
    u.outcome = this->check_measurement(model, z, u.r);
    if (u.outcome == FilterOutcome::kApplied) u.outcome = linearize_at(model, z, this->x_, u.innovation, u.h);
    if (u.outcome != FilterOutcome::kApplied) return u;
    u.s.emplace(u.h * this->p_ * u.h.transpose() + u.r);
    if (!u.s->ok()) u.outcome = FilterOutcome::kSingularInnovation;
    return u;
  }

  // h and its Jacobian at x, and the innovation z (-) h(x) (the model's angle-aware residual).
  // kNonFinite when the model gives a non-finite number, kSizeMismatch when its Jacobian does not
  // fit the state.
  template <class Model>
  FilterOutcome linearize_at(const Model& model, const typename Model::Vector& z, const State& x,
                             Vec<Model::kSize>& innovation, Mat<Model::kSize, N>& h) const {
    MeasurementLinearization<Model::kSize, N> lin = model.linearize(x);
    if (lin.jacobian.rows() != model.size() || lin.jacobian.cols() != x.size() ||
        lin.predicted.size() != model.size()) {
      return FilterOutcome::kSizeMismatch;
    }
    if (!lin.predicted.allFinite() || !lin.jacobian.allFinite()) return FilterOutcome::kNonFinite;
    innovation = model.residual(z, lin.predicted);
    h = std::move(lin.jacobian);
    return FilterOutcome::kApplied;
  }
  // The Kalman gain K = P H^T S^-1, as (S^-1 H P)^T since S and P are symmetric.
  template <int M>
  Mat<N, M> gain(const Mat<M, N>& h, const InnovationFactor<M>& s) const {
    return s.solve(h * this->p_).transpose();
  }
  // P = (I - K H) P (I - K H)^T + K R K^T (Joseph form: symmetric and positive semi-definite
  // whatever the rounding in K).
  template <int M>
  void joseph_update(const Mat<N, M>& k, const Mat<M, N>& h, const Mat<M, M>& r) {
    const Covariance i_kh = Covariance::Identity(this->p_.rows(), this->p_.cols()) - k * h;
    this->p_ = symmetrized(Covariance(i_kh * this->p_ * i_kh.transpose() + k * r * k.transpose()));
  }
};

}  // namespace beaconloc
