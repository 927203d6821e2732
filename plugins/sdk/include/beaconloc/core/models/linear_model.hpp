#pragma once
// A linear measurement z = H x + v, v ~ N(0, R), on a state of N numbers: the textbook Kalman
// filter's model, and a direct observation of some states (seed 000's distance estimates,
// eq. 25-27: H selects the measured receiver's distance).
#include "beaconloc/core/models/model_concepts.hpp"

namespace beaconloc {

template <int M, int N>
class LinearModel {
 public:
  static constexpr int kSize = M;
  static constexpr bool kHasJacobian = true;
  static constexpr bool kPlainResidual = true;  // z - h: no angle in z
  using Vector = Vec<M>;

  LinearModel(const Mat<M, N>& h, const Mat<M, M>& r) : h_(h), r_(r) {}

  Eigen::Index size() const { return h_.rows(); }
  Vector predict(const Vec<N>& x) const { return h_ * x; }
  MeasurementLinearization<M, N> linearize(const Vec<N>& x) const { return {h_ * x, h_}; }
  Mat<M, M> noise() const { return r_; }
  Vector residual(const Vector& z, const Vector& h) const { return z - h; }

 private:
  Mat<M, N> h_;
  Mat<M, M> r_;
};

}  // namespace beaconloc
