#pragma once
// The space a filter's state lives in: its dimension and its composition. A state is a vector of
// N numbers of which some are headings; x (+) dx and a (-) b wrap those to (-pi, pi], so that a
// filter adds a correction, averages sigma points or takes a difference of states in one place
// and no caller wraps a heading after it (issue 14). N is fixed where the size is known
// (Eigen::Dynamic where the state grows: beacons calibrated in the state).
#include <Eigen/Core>
#include <cstdint>
#include <initializer_list>
#include <stdexcept>

#include "beaconloc/core/pose2.hpp"

namespace beaconloc {

template <int N>
using Vec = Eigen::Matrix<double, N, 1>;
template <int M, int N>
using Mat = Eigen::Matrix<double, M, N>;

// Where the planar pose sits in a state: the indices of x_m, y_m and yaw_rad.
struct PoseIndex {
  Eigen::Index x = 0;
  Eigen::Index y = 1;
  Eigen::Index yaw = 2;
  template <class V>
  Pose2 pose_of(const V& state) const {
    return {state(x), state(y), state(yaw)};
  }
};

template <int N>
class StateSpace {
 public:
  using Vector = Vec<N>;
  // angles: the indices of the headings, each below 64 (a dynamic state keeps its pose at the
  // front). dimension: N, or the size of a dynamic state. Throws std::invalid_argument on an
  // index outside the state.
  explicit StateSpace(std::initializer_list<Eigen::Index> angles = {}, Eigen::Index dimension = N)
      : dimension_(dimension) {
    if (dimension_ < 1 || (N != Eigen::Dynamic && dimension_ != N)) {
      throw std::invalid_argument("StateSpace: the dimension must be N, or positive for a dynamic state");
    }
    for (const Eigen::Index i : angles) {
      if (i < 0 || i >= dimension_ || i >= 64) throw std::invalid_argument("StateSpace: angle index outside the state");
      angle_mask_ |= std::uint64_t{1} << i;
    }
  }
  // The space of a state holding a pose at `pose` (its heading wrapped), the rest Euclidean.
  static StateSpace with_pose(const PoseIndex& pose = {}, Eigen::Index dimension = N) {
    return StateSpace({pose.yaw}, dimension);
  }

  Eigen::Index dimension() const { return dimension_; }
  bool is_angle(Eigen::Index i) const { return i < 64 && ((angle_mask_ >> i) & 1u) != 0; }

  // x (+) dx: the state moved by dx, its headings wrapped.
  template <class A, class B>
  Vector plus(const Eigen::MatrixBase<A>& x, const Eigen::MatrixBase<B>& dx) const {
    Vector out = x + dx;
    wrap(out);
    return out;
  }
  // a (-) b: the step from b to a, its heading components wrapped.
  template <class A, class B>
  Vector minus(const Eigen::MatrixBase<A>& a, const Eigen::MatrixBase<B>& b) const {
    Vector out = a - b;
    wrap(out);
    return out;
  }
  // The headings of v that lie outside (-pi, pi] wrapped into it; those inside stay bit for bit
  // (a belief given to a filter as it is).
  void normalize(Vector& v) const {
    for (std::uint64_t m = angle_mask_; m != 0; m &= m - 1) {
      const int i = __builtin_ctzll(m);
      if (!(v(i) > -M_PI && v(i) <= M_PI)) v(i) = wrap_angle_rad(v(i));
    }
  }
  // The headings of v wrapped to (-pi, pi].
  void wrap(Vector& v) const {
    for (std::uint64_t m = angle_mask_; m != 0; m &= m - 1) {
      const int i = __builtin_ctzll(m);
      v(i) = wrap_angle_rad(v(i));
    }
  }

 private:
  Eigen::Index dimension_;
  std::uint64_t angle_mask_ = 0;
};

// The pose [x, y, yaw] alone.
using PoseSpace = StateSpace<3>;
inline PoseSpace pose_space() { return PoseSpace::with_pose(); }

}  // namespace beaconloc
