#pragma once
// Chi-square quantiles for consistency tests over a varying number of terms.
#include <cmath>

namespace beaconloc {

// The 99.9 % quantiles of chi-square at 1 and 3 dof: the gates of one range, one pose.
inline constexpr double kChiSquare999OneDof = 10.83;
inline constexpr double kChiSquare999ThreeDof = 16.27;
// The 99.73 % quantile of chi-square at 2 dof, -2 ln(0.0027): a 2D error outside its covariance's
// 3-sigma ellipse.
inline constexpr double kChiSquare2Dof3Sigma = 11.83;

// The 99.9 % quantile of chi-square with dof degrees of freedom, by Wilson-Hilferty: above
// the exact value by 3 % at 1 dof, 1.2 % at 5, 0.3 % at 20.
inline double chi_square_quantile_999(int dof) {
  constexpr double kZ999 = 3.0902;  // the standard normal's 99.9 % quantile
  const double k = static_cast<double>(dof);
  const double a = 2.0 / (9.0 * k);
  return k * std::pow(1.0 - a + kZ999 * std::sqrt(a), 3);
}

}  // namespace beaconloc
