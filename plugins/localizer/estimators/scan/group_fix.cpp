#include "scan/group_fix.hpp"

#include <Eigen/Cholesky>
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <optional>

#include "beaconloc/core/chi_square.hpp"

#include "beaconloc/core/models/range_difference_model.hpp"
#include "beaconloc/core/models/range_model.hpp"

namespace beaconloc::scan {
namespace {

// h, dh/d[x, y] and R at a position (heading 0: the receiver at the centre does not see it).
struct Linearized {
  Eigen::VectorXd residual;
  Eigen::MatrixXd jacobian;  // rows x 2
  Eigen::MatrixXd noise;
};

Linearized linearize(const GroupMeasurements& m, const Eigen::Vector2d& p) {
  const Vec<3> pose(p.x(), p.y(), 0.0);
  const double variance = m.range_sigma_m * m.range_sigma_m;
  Linearized out;
  const auto n = static_cast<Eigen::Index>(m.beacons_m.size());
  if (m.geometry == Geometry::kSpherical) {
    out.residual.resize(n);
    out.jacobian.resize(n, 2);
    for (Eigen::Index i = 0; i < n; ++i) {
      const RangeModel model(Eigen::Vector2d::Zero(), m.receiver_z_m, m.beacons_m[i], variance);
      const auto lin = model.linearize(pose);
      out.residual(i) = m.ranges_m[i] - lin.predicted(0);
      out.jacobian.row(i) = lin.jacobian.leftCols<2>();
    }
    out.noise = Eigen::MatrixXd::Identity(n, n) * variance;  // eq. 18
  } else {
    // Eq. 19's sigma_vT^2 is a difference's variance: two independent ranges, 2 sigma_v^2 (and
    // sigma_v^2, its half, between two differences sharing the reference).
    const RangeDifferenceModel model(Eigen::Vector2d::Zero(), m.receiver_z_m, m.beacons_m, 2.0 * variance);
    const auto lin = model.linearize(pose);
    Eigen::VectorXd z(n - 1);
    for (Eigen::Index i = 1; i < n; ++i) z(i - 1) = m.ranges_m[i] - m.ranges_m[0];  // eq. 27
    out.residual = z - lin.predicted;
    out.jacobian = lin.jacobian.leftCols(2);
    out.noise = model.noise();  // eq. 19
  }
  return out;
}

GroupFix failed(GroupFixFailure why, int iterations = 0) {
  GroupFix f;
  f.failure = why;
  f.iterations = iterations;
  return f;
}

}  // namespace

const char* to_string(GroupFixFailure failure) {
  switch (failure) {
    case GroupFixFailure::kNone: return "none";
    case GroupFixFailure::kTooFewBeacons: return "too_few_beacons";
    case GroupFixFailure::kNonFinite: return "non_finite";
    case GroupFixFailure::kSingular: return "singular";
    case GroupFixFailure::kNotConverged: return "not_converged";
    case GroupFixFailure::kResidualTooLarge: return "residual_too_large";
    case GroupFixFailure::kEchoUnidentified: return "echo_unidentified";
  }
  return "unknown";
}

std::size_t ranges_for_a_fix(Geometry g) { return g == Geometry::kSpherical ? 3 : 4; }

GroupFix solve_group_fix(const GroupMeasurements& m, const GroupFixSettings& settings) {
  if (m.beacons_m.size() != m.ranges_m.size() || m.beacons_m.size() < ranges_for_a_fix(m.geometry)) {
    return failed(GroupFixFailure::kTooFewBeacons);
  }
  Eigen::Vector2d p = Eigen::Vector2d::Zero();
  for (std::size_t i = 0; i < m.beacons_m.size(); ++i) {
    if (!m.beacons_m[i].allFinite() || !std::isfinite(m.ranges_m[i])) return failed(GroupFixFailure::kNonFinite);
    p += m.beacons_m[i].head<2>();
  }
  if (!std::isfinite(m.receiver_z_m) || !(m.range_sigma_m > 0.0) || !std::isfinite(m.range_sigma_m)) {
    return failed(GroupFixFailure::kNonFinite);
  }
  p /= static_cast<double>(m.beacons_m.size());
  GroupFix fix;
  for (fix.iterations = 1; fix.iterations <= settings.max_iterations; ++fix.iterations) {
    const Linearized lin = linearize(m, p);
    const Eigen::LDLT<Eigen::MatrixXd> r(lin.noise);
    const Eigen::MatrixXd rj = r.solve(lin.jacobian);
    const Eigen::Matrix2d normal = lin.jacobian.transpose() * rj;
    const Eigen::LDLT<Eigen::Matrix2d> n(normal);
    if (r.info() != Eigen::Success || n.info() != Eigen::Success || !n.isPositive() ||
        !(n.vectorD().array() > 1e-12 * normal.trace()).all()) {
      return failed(GroupFixFailure::kSingular, fix.iterations);
    }
    const Eigen::Vector2d step = n.solve(rj.transpose() * lin.residual);
    if (!step.allFinite()) return failed(GroupFixFailure::kNonFinite, fix.iterations);
    p += step;
    if (step.norm() < settings.tolerance_m) {
      const Linearized at = linearize(m, p);
      const Eigen::LDLT<Eigen::MatrixXd> ra(at.noise);
      const Eigen::Matrix2d information = at.jacobian.transpose() * ra.solve(at.jacobian);
      fix.position_m = p;
      const Eigen::LDLT<Eigen::Matrix2d> li(information);
      if (li.info() != Eigen::Success || !li.isPositive()) return failed(GroupFixFailure::kSingular, fix.iterations);
      fix.covariance_m2 = li.solve(Eigen::Matrix2d::Identity());
      const double chi2 = at.residual.dot(ra.solve(at.residual));
      fix.residual_rms_sigma = std::sqrt(chi2 / static_cast<double>(at.residual.size()));
      if (!fix.covariance_m2.allFinite() || !p.allFinite()) return failed(GroupFixFailure::kNonFinite, fix.iterations);
      // m residuals, 2 unknowns fitted: m - 2 degrees of freedom (at least 1: three ranges or
      // three differences at the least).
      const int dof = std::max(1, static_cast<int>(at.residual.size()) - 2);
      if (!(chi2 <= chi_square_quantile_999(dof))) {
        fix.failure = GroupFixFailure::kResidualTooLarge;
      }
      return fix;
    }
  }
  return failed(GroupFixFailure::kNotConverged, settings.max_iterations);
}

GroupFixWithoutAnEcho solve_group_fix_without_an_echo(const GroupMeasurements& m, const GroupFixSettings& settings) {
  GroupFixWithoutAnEcho out{solve_group_fix(m, settings), std::nullopt};
  const bool spoiled = out.fix.failure == GroupFixFailure::kResidualTooLarge ||
                       out.fix.failure == GroupFixFailure::kNotConverged ||
                       out.fix.failure == GroupFixFailure::kSingular;
  // (Mismatched sizes are kTooFewBeacons, not spoiled.)
  if (!spoiled || m.geometry != Geometry::kSpherical || m.ranges_m.size() < ranges_for_a_fix(m.geometry) + 1) {
    return out;
  }
  const double variance_m2 = m.range_sigma_m * m.range_sigma_m;
  std::optional<GroupFixWithoutAnEcho> found;
  for (std::size_t skip = 0; skip < m.ranges_m.size(); ++skip) {
    GroupMeasurements subset = m;
    subset.beacons_m.erase(subset.beacons_m.begin() + static_cast<std::ptrdiff_t>(skip));
    subset.ranges_m.erase(subset.ranges_m.begin() + static_cast<std::ptrdiff_t>(skip));
    const GroupFix fix = solve_group_fix(subset, settings);
    if (!fix.ok()) continue;
    // The left-out range against the one the subset's fix predicts, in sigmas of the range and of
    // the prediction (the fix is made of the other ranges: the two are independent).
    const auto left = RangeModel(Eigen::Vector2d::Zero(), m.receiver_z_m, m.beacons_m[skip], variance_m2)
                          .linearize(Vec<3>(fix.position_m.x(), fix.position_m.y(), 0.0));
    const Eigen::RowVector2d jacobian = left.jacobian.leftCols<2>();
    const double excess_m = m.ranges_m[skip] - left.predicted(0);
    const double sigma_m = std::sqrt(variance_m2 + jacobian * fix.covariance_m2 * jacobian.transpose());
    if (!(excess_m > kEchoExcessSigma * sigma_m)) continue;
    if (found) {
      out.fix.failure = GroupFixFailure::kEchoUnidentified;
      return out;
    }
    found = GroupFixWithoutAnEcho{fix, skip};
  }
  return found ? *found : out;
}

}  // namespace beaconloc::scan
