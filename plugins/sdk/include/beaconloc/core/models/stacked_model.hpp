#pragma once
// Several measurements taken as one (core/models/model_concepts.hpp): ModelList<Part> stacks any
// number of models of one type (the ranges of one update, the batch of a Gauss-Newton solve),
// StackedModel<A, B> stacks two models (seed 001 eq. 16: the beacon ranges, then the laser beams).
// h and z are the parts' one after another, R is block-diagonal (the parts' noises independent),
// the residual is each part's (angle-aware where the part is), and the Jacobian is the parts'
// rows, present only when every part has one (kHasJacobian).
#include <cstddef>
#include <utility>
#include <vector>

#include "beaconloc/core/models/model_concepts.hpp"

namespace beaconloc {

template <class Part>
class ModelList : public PredictsByWritingInPlace<ModelList<Part>>, public NoiseByWritingInPlace<ModelList<Part>> {
 public:
  static constexpr int kSize = Eigen::Dynamic;
  static constexpr bool kHasJacobian = Part::kHasJacobian;
  static constexpr bool kPlainResidual = plain_residual_v<Part>;
  using Vector = Eigen::VectorXd;

  ModelList() = default;
  explicit ModelList(std::vector<Part> parts) : parts_(std::move(parts)) {
    for (const Part& p : parts_) size_ += p.size();
  }
  void add(Part part) {
    size_ += part.size();
    parts_.push_back(std::move(part));
  }
  const std::vector<Part>& parts() const { return parts_; }

  Eigen::Index size() const { return size_; }
  template <int N>
  void predict_into(const Vec<N>& x, Eigen::Ref<Eigen::VectorXd> out) const {
    Eigen::Index at = 0;
    for (const Part& p : parts_) {
      beaconloc::predict_into(p, x, out.segment(at, p.size()));
      at += p.size();
    }
  }
  template <int N>
  MeasurementLinearization<Eigen::Dynamic, N> linearize(const Vec<N>& x) const {
    MeasurementLinearization<Eigen::Dynamic, N> out;
    out.predicted.resize(size_);
    out.jacobian.resize(size_, x.size());
    Eigen::Index at = 0;
    for (const Part& p : parts_) {
      const auto one = p.linearize(x);
      out.predicted.segment(at, p.size()) = one.predicted;
      out.jacobian.middleRows(at, p.size()) = one.jacobian;
      at += p.size();
    }
    return out;
  }
  void noise_into(Eigen::Ref<Eigen::MatrixXd> r) const {
    Eigen::Index at = 0;
    for (const Part& p : parts_) {
      if constexpr (Part::kSize != Eigen::Dynamic && !WritesNoiseInPlace<Part>::value) {
        r.template block<Part::kSize, Part::kSize>(at, at) = p.noise();  // a fixed-size block
      } else {
        beaconloc::noise_into(p, r.block(at, at, p.size(), p.size()));
      }
      at += p.size();
    }
  }
  Vector residual(const Vector& z, const Vector& h) const {
    Vector out(size_);
    Eigen::Index at = 0;
    for (const Part& p : parts_) {
      const Eigen::Index m = p.size();
      out.segment(at, m) =
          p.residual(typename Part::Vector(z.segment(at, m)), typename Part::Vector(h.segment(at, m)));
      at += m;
    }
    return out;
  }

 private:
  std::vector<Part> parts_;
  Eigen::Index size_ = 0;
};

template <class A, class B>
class StackedModel : public PredictsByWritingInPlace<StackedModel<A, B>>,
                     public NoiseByWritingInPlace<StackedModel<A, B>> {
 public:
  static constexpr int kSize = Eigen::Dynamic;
  static constexpr bool kHasJacobian = A::kHasJacobian && B::kHasJacobian;
  static constexpr bool kPlainResidual = plain_residual_v<A> && plain_residual_v<B>;
  using Vector = Eigen::VectorXd;

  StackedModel(A first, B second) : first_(std::move(first)), second_(std::move(second)) {}

  Eigen::Index size() const { return first_.size() + second_.size(); }
  template <int N>
  void predict_into(const Vec<N>& x, Eigen::Ref<Eigen::VectorXd> out) const {
    beaconloc::predict_into(first_, x, out.head(first_.size()));
    beaconloc::predict_into(second_, x, out.tail(second_.size()));
  }
  template <int N>
  MeasurementLinearization<Eigen::Dynamic, N> linearize(const Vec<N>& x) const {
    const auto a = first_.linearize(x);
    const auto b = second_.linearize(x);
    MeasurementLinearization<Eigen::Dynamic, N> out;
    const Eigen::Index m = first_.size(), k = second_.size();
    out.predicted.resize(size());
    out.predicted.head(m) = a.predicted;
    out.predicted.tail(k) = b.predicted;
    out.jacobian.resize(size(), x.size());
    out.jacobian.topRows(m) = a.jacobian;
    out.jacobian.bottomRows(k) = b.jacobian;
    return out;
  }
  void noise_into(Eigen::Ref<Eigen::MatrixXd> r) const {
    beaconloc::noise_into(first_, r.topLeftCorner(first_.size(), first_.size()));
    beaconloc::noise_into(second_, r.bottomRightCorner(second_.size(), second_.size()));
  }
  Vector residual(const Vector& z, const Vector& h) const {
    const Eigen::Index m = first_.size(), k = second_.size();
    Vector out(size());
    out.head(m) = first_.residual(typename A::Vector(z.head(m)), typename A::Vector(h.head(m)));
    out.tail(k) = second_.residual(typename B::Vector(z.tail(k)), typename B::Vector(h.tail(k)));
    return out;
  }

 private:
  A first_;
  B second_;
};

}  // namespace beaconloc
