#pragma once
// A linear motion x' = F x + B u, with noise G w on the input (w ~ N(0, U)) and Q on the state:
// the textbook Kalman filter's model, for pinning the filters to it (tests/unit/filter_equivalence_test).
#include "beaconloc/core/models/model_concepts.hpp"

namespace beaconloc {

template <int N, int U>
class LinearMotion {
 public:
  static constexpr int kInputSize = U;
  static constexpr bool kHasStateNoise = true;
  using Input = Vec<U>;

  LinearMotion(const Mat<N, N>& f, const Mat<N, U>& b, const Mat<U, U>& input_covariance, const Mat<N, N>& q)
      : f_(f), b_(b), u_cov_(input_covariance), q_(q) {}

  Vec<N> step(const Vec<N>& x, const Input& u, double /*dt_s*/) const { return f_ * x + b_ * u - x; }
  MotionLinearization<N, U> linearize(const Vec<N>& x, const Input& u, double dt_s) const {
    return {step(x, u, dt_s), f_, b_};
  }
  Mat<U, U> input_noise(const Input& /*u*/) const { return u_cov_; }
  template <int M>
  Mat<M, M> state_noise(Eigen::Index /*n*/, double /*dt_s*/) const {
    return q_;
  }

 private:
  Mat<N, N> f_;
  Mat<N, U> b_;
  Mat<U, U> u_cov_;
  Mat<N, N> q_;
};

}  // namespace beaconloc
