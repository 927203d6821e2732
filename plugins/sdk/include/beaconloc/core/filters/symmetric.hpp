#pragma once
// A covariance made exactly symmetric after an update's rounding: (P + P^T) / 2, evaluated into a
// temporary. Written in place as `p = 0.5 * (p + p.transpose())` Eigen reads entries it has
// already overwritten (transpose aliasing) and the result is not symmetric at all.
#include <Eigen/Core>

namespace beaconloc {

template <class Derived>
typename Derived::PlainObject symmetrized(const Eigen::MatrixBase<Derived>& m) {
  return (0.5 * (m + m.transpose())).eval();
}

}  // namespace beaconloc
