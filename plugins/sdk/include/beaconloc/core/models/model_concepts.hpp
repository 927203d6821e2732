#pragma once
// What a filter (core/filters: EKF, iterated EKF, UKF, H-infinity) asks of its models, so that
// every filter runs over every model (issue 14; the design of mherb/kalman).
//
// A measurement model:
//   static constexpr int kSize;          // M, the measurement's size; Eigen::Dynamic when it varies
//   static constexpr bool kHasJacobian;  // false: only the UKF, which needs no Jacobian, takes it
//   using Vector = Vec<kSize>;
//   Eigen::Index size() const;                                  // M
//   template <int N> Vector predict(const Vec<N>& x) const;     // h(x)
//   template <int N> MeasurementLinearization<kSize, N>
//       linearize(const Vec<N>& x) const;                       // h(x) and dh/dx (kHasJacobian)
//   Mat<kSize, kSize> noise() const;                            // R
//   Vector residual(const Vector& z, const Vector& h) const;    // z - h, angles wrapped
//   template <int N> void predict_into(const Vec<N>& x, Eigen::Ref<Eigen::VectorXd> h) const;
//                                          // optional: h(x) written in place (no allocation; the
//                                          // UKF calls it once per sigma point)
//   void noise_into(Eigen::Ref<Eigen::MatrixXd> r) const;
//                                          // optional: R written into r, which is zero on entry
//                                          // (a block-diagonal model writes its blocks, and no
//                                          // part allocates a matrix of its own)
//   static constexpr bool kPlainResidual;  // optional: true when residual() is z - h exactly
//                                          // (no angle in z); the UKF then centres its sigma
//                                          // points' predictions at once, not one call per point
//
// A motion model moves a state by an input u over dt_s. It gives the step dx, and the filter
// composes x (+) dx in its state space (core/filters/state_space.hpp), so that headings are
// wrapped there and nowhere else:
//   static constexpr int kInputSize;
//   static constexpr bool kHasStateNoise;   // true: state_noise() adds Q on the state
//   using Input = Vec<kInputSize>;
//   template <int N> Vec<N> step(const Vec<N>& x, const Input& u, double dt_s) const;   // dx
//   template <int N> MotionLinearization<N, kInputSize>
//       linearize(const Vec<N>& x, const Input& u, double dt_s) const;               // dx, F, G
//   Mat<kInputSize, kInputSize> input_noise(const Input& u) const;                     // U
//   template <int N> Mat<N, N> state_noise(Eigen::Index n, double dt_s) const;        // Q, when kHasStateNoise
// The EKF's predicted covariance is F P F^T + G U G^T (+ Q); the UKF propagates sigma points of
// the state augmented with the input noise.
#include <type_traits>
#include <utility>

#include "beaconloc/core/filters/state_space.hpp"

namespace beaconloc {

// Model::kPlainResidual, false for a model that does not say.
template <class Model, class = void>
struct PlainResidual : std::false_type {};
template <class Model>
struct PlainResidual<Model, std::void_t<decltype(Model::kPlainResidual)>>
    : std::bool_constant<Model::kPlainResidual> {};
template <class Model>
inline constexpr bool plain_residual_v = PlainResidual<Model>::value;

// Whether Model has predict_into (for a state of N numbers).
template <class Model, int N, class = void>
struct PredictsInPlace : std::false_type {};
template <class Model, int N>
struct PredictsInPlace<Model, N,
                       std::void_t<decltype(std::declval<const Model&>().predict_into(
                           std::declval<const Vec<N>&>(), std::declval<Eigen::Ref<Eigen::VectorXd>>()))>>
    : std::true_type {};
// h(x) into `out` (model.size() numbers): in place where the model can, else a copy of predict().
template <int N, class Model>
void predict_into(const Model& model, const Vec<N>& x, Eigen::Ref<Eigen::VectorXd> out) {
  if constexpr (PredictsInPlace<Model, N>::value) {
    model.predict_into(x, out);
  } else {
    out = model.predict(x);
  }
}

// For a model of dynamic size that writes h in place: its predict(), from its predict_into()
// (CRTP: class Model : public PredictsByWritingInPlace<Model>).
template <class Model>
struct PredictsByWritingInPlace {
  template <int N>
  Eigen::VectorXd predict(const Vec<N>& x) const {
    const Model& model = static_cast<const Model&>(*this);
    Eigen::VectorXd out(model.size());
    model.predict_into(x, out);
    return out;
  }
};

// Whether Model has noise_into.
template <class Model, class = void>
struct WritesNoiseInPlace : std::false_type {};
template <class Model>
struct WritesNoiseInPlace<
    Model, std::void_t<decltype(std::declval<const Model&>().noise_into(std::declval<Eigen::Ref<Eigen::MatrixXd>>()))>>
    : std::true_type {};
// R into `r` (model.size() square, zero on entry): in place where the model can, else a copy of
// noise().
template <class Model>
void noise_into(const Model& model, Eigen::Ref<Eigen::MatrixXd> r) {
  if constexpr (WritesNoiseInPlace<Model>::value) {
    model.noise_into(r);
  } else {
    r = model.noise();
  }
}

// For a model of dynamic size that writes R in place: its noise(), from its noise_into() (CRTP:
// class Model : public NoiseByWritingInPlace<Model>).
template <class Model>
struct NoiseByWritingInPlace {
  Eigen::MatrixXd noise() const {
    const Model& model = static_cast<const Model&>(*this);
    Eigen::MatrixXd r = Eigen::MatrixXd::Zero(model.size(), model.size());
    model.noise_into(r);
    return r;
  }
};

template <int M, int N>
struct MeasurementLinearization {
  Vec<M> predicted;     // h(x)
  Mat<M, N> jacobian;   // dh/dx at x
};

template <int N, int U>
struct MotionLinearization {
  Vec<N> step;               // dx: the next state is x (+) dx
  Mat<N, N> jacobian_state;  // F = d(x (+) dx)/dx
  Mat<N, U> jacobian_input;  // G = d(x (+) dx)/du
};

}  // namespace beaconloc
