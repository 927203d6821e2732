#pragma once
// Seed 003 Sec. 3.2-3.3: the robot's first position in one frame (the global one, or a LRULPS's)
// from one group's measurements, by Gauss-Newton (eq. 4 and 7): spherical, the ranges to the
// group's beacons (eq. 5 and 8); hyperbolic, the ranges to beacons 2..I minus the range to the
// first (eq. 6 and 9), whose noise is correlated (eq. 19). One receiver at the robot's centre at a
// known height z_MR, so only the position is found; the heading comes from two fixes (Fig. 5, 7).
// The measurement models are the core's (RangeModel, RangeDifferenceModel), the same the filters use.
#include <Eigen/Core>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <vector>

namespace beaconloc::scan {

enum class Geometry : std::uint8_t { kSpherical, kHyperbolic };

enum class GroupFixFailure : std::uint8_t {
  kNone,
  kTooFewBeacons,     // under three ranges (spherical) or four beacons (hyperbolic; Sec. 2)
  kNonFinite,         // a beacon, a range or the result not finite
  kSingular,          // the normal equations could not be solved (beacons in a line under the robot)
  kNotConverged,      // no step under the tolerance within the iterations
  kResidualTooLarge,  // the fix does not explain its measurements (an echo, a wrong beacon): the
                      // whitened residuals' chi-square above its 99.9 % quantile for m - 2 dof
  kEchoUnidentified,  // the fix of them all failed, and more than one range could be the echo
                      // (solve_group_fix_without_an_echo)
};
const char* to_string(GroupFixFailure failure);

struct GroupMeasurements {
  Geometry geometry = Geometry::kSpherical;
  std::vector<Eigen::Vector3d> beacons_m;  // in the frame solved in; hyperbolic: the reference first
  std::vector<double> ranges_m;            // one per beacon, as measured (hyperbolic: differenced here)
  double receiver_z_m = 0.0;               // z_MR
  double range_sigma_m = 0.005;            // sigma_v (Sec. 4)
};

struct GroupFixSettings {
  int max_iterations = 50;  // Gauss-Newton converges slowly where the residuals are large (an echo)
  double tolerance_m = 1e-6;
};

struct GroupFix {
  GroupFixFailure failure = GroupFixFailure::kNone;
  Eigen::Vector2d position_m = Eigen::Vector2d::Zero();
  Eigen::Matrix2d covariance_m2 = Eigen::Matrix2d::Identity();  // (J^T R^-1 J)^-1 at the fix
  double residual_rms_sigma = 0.0;  // whitened residuals' RMS (for people; the gate is on their chi-square)
  int iterations = 0;
  bool ok() const { return failure == GroupFixFailure::kNone; }
};

// Sec. 2: three ranges at least for a spherical fix, four beacons for a hyperbolic one.
std::size_t ranges_for_a_fix(Geometry g);

// Starts under the group's centroid (the robot hears the group: it is within its coverage).
GroupFix solve_group_fix(const GroupMeasurements& m, const GroupFixSettings& settings = {});

// Not in the paper: an echo (a reflection's longer path) spoils one range of an epoch, and the fix
// of them all fails. Spherical, with a range more than a fix needs: each range is left out in
// turn, and the fix is that of the one subset whose own fix passes its gate and predicts the range
// it left out shorter than measured by more than kEchoExcessSigma of that range (an echo is only
// ever longer). More than one such subset: kEchoUnidentified; none, or hyperbolic (three
// differences of four beacons leave one degree of freedom, and a wrong subset fits as well as
// the right one): the fix of them all, with its failure.
inline constexpr double kEchoExcessSigma = 3.0;
struct GroupFixWithoutAnEcho {
  GroupFix fix;
  std::optional<std::size_t> left_out;  // the range left out, as an index into the measurements
};
GroupFixWithoutAnEcho solve_group_fix_without_an_echo(const GroupMeasurements& m,
                                                      const GroupFixSettings& settings = {});

}  // namespace beaconloc::scan
