#pragma once
// Iterated extended Kalman filter (seed 002 Sec. 4; ERRATA: re-linearize h about the updated state
// and repeat until it converges): the Gauss-Newton iteration of the update's MAP problem,
//   x_{i+1} = x0 (+) K_i (z (-) h(x_i) - H_i (x0 (-) x_i)),  K_i = P H_i^T (H_i P H_i^T + R)^-1,
// H_i the Jacobian at x_i, from x_0 = the prior; it stops when a step moves the state by at most
// step_tolerance (the norm of x_{i+1} (-) x_i) or after max_iterations linearizations. The
// covariance is updated in Joseph form with the last K_i and H_i. One iteration is the EKF.
// Prediction as the EKF's (gaussian_filter.hpp).
#include <cmath>
#include <limits>

#include "beaconloc/core/filters/gaussian_filter.hpp"

namespace beaconloc {

struct IteratedEkfOptions {
  int max_iterations = 10;
  double step_tolerance = 1e-9;  // in the state's units (m, rad, s, ...), as a Euclidean norm
};

template <int N>
class IteratedEkf : public LinearizedFilter<N> {
 public:
  using typename LinearizedFilter<N>::Space;
  using typename LinearizedFilter<N>::State;
  using typename LinearizedFilter<N>::Covariance;
  explicit IteratedEkf(Space space = Space(), IteratedEkfOptions options = {})
      : LinearizedFilter<N>(space), options_(options) {
    if (options_.max_iterations < 1) options_.max_iterations = 1;
  }
  const IteratedEkfOptions& options() const { return options_; }

  // Gated on the NIS at the prior (the first linearization). Not applied (state unchanged) on a
  // gate, a singular innovation covariance at any iterate, or a non-finite model output.
  template <class Model>
  UpdateResult update(const Model& model, const typename Model::Vector& z,
                      double nis_gate = std::numeric_limits<double>::infinity()) {
    static_assert(Model::kHasJacobian, "the IEKF linearizes its measurement model: this model has no Jacobian");
    constexpr int M = Model::kSize;
    UpdateResult result;
    const Mat<M, M> r = model.noise();
    result.outcome = this->check_measurement(model, z, r);
    if (!result.applied()) return result;
    const State x0 = this->x_;
    State xi = x0;
    Mat<N, M> k = Mat<N, M>::Zero(x0.size(), model.size());
    Mat<M, N> h = Mat<M, N>::Zero(model.size(), x0.size());
    for (int i = 0; i < options_.max_iterations; ++i) {
      Vec<M> innovation;
      result.outcome = this->linearize_at(model, z, xi, innovation, h);
      if (!result.applied()) return result;
      const InnovationFactor<M> s(h * this->p_ * h.transpose() + r);
      if (!s.ok()) {
        result.outcome = FilterOutcome::kSingularInnovation;
        return result;
      }
      if (i == 0) {
        result.nis = s.nis(innovation);
        result.log_det_s = s.log_det();
        if (!(result.nis <= nis_gate)) {
          result.outcome = FilterOutcome::kGated;
          return result;
        }
      } else {
        innovation -= h * this->space_.minus(x0, xi);
      }
      k = this->gain(h, s);
      const State next = this->space_.plus(x0, k * innovation);
      result.iterations = i + 1;
      const double step = this->space_.minus(next, xi).norm();
      xi = next;
      if (!std::isfinite(step)) {
        result.outcome = FilterOutcome::kNonFinite;
        return result;
      }
      if (step <= options_.step_tolerance) break;
    }
    this->x_ = xi;
    this->joseph_update(k, h, r);
    return result;
  }

 private:
  IteratedEkfOptions options_;
};

}  // namespace beaconloc
