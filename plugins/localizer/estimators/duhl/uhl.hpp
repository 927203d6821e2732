#pragma once
// UHL, the ultrasonic hybrid localization of seed 000 (Kim & Kim 2013), Section II-B: the pose
// of a robot carrying three receivers equilaterally on a circle of radius r_R (eq. 1) from the
// distances between those receivers and N >= 2 ceiling Txs, with no prior.
//  - direct method (DM): orientation from the stacked A Phi = b (eq. 4), refined under the unit-norm
//    constraint through the quartic in sin(phi) (eq. 5-8), the root closest to the pseudoinverse
//    solution (eq. 9); position by the linearized spherical interpolation (eq. 10);
//  - indirect method using ranges (IMR): the range rho_i from the robot centre to each Tx by the
//    isotropic-array property (eq. 11), multilateration, and for collinear Txs the circle
//    intersections split by the side of the Tx line (eq. 12-13), the side chosen by the DM;
//  - the selection of Table I with the collinearity threshold d_th.
// Pure maths: no DDS, no clock.
#include <optional>
#include <string>
#include <vector>

#include "beaconloc/core/pose2.hpp"

namespace beaconloc::duhl {

// The distances d^i = [d_1^i, d_2^i, d_3^i] from Tx i to the three receivers (eq. 3).
struct TxDistances {
  Eigen::Vector3d tx_map_m = Eigen::Vector3d::Zero();
  Eigen::Vector3d distances_m = Eigen::Vector3d::Zero();
};

struct UhlOptions {
  double receiver_radius_m = 0.19;  // r_R (eq. 1; Sec. V: 0.19 m)
  double receiver_height_m = 0.0;   // the receivers' plane (the paper: z = 0)
  // Table I, line 3: with collinear Txs, a DM position closer than d_th to their line is kept
  // (the IMR's circles meet at grazing angles there). The paper sets d_th experimentally from
  // the Tx spacing and z_T without printing it; 0.3 m is our choice (Tx spacing ~1.5 m, z_T ~2 m).
  double collinear_threshold_m = 0.3;
  // Txs count as collinear when their spread across the line through them is below this (RMS).
  double collinearity_tolerance_m = 0.05;
};

enum class UhlMethod { kDirect, kIndirect };

struct UhlSolution {
  bool ok = false;
  Pose2 pose = Pose2::Zero();
  UhlMethod method = UhlMethod::kDirect;
  Eigen::Vector2d direct_position_m = Eigen::Vector2d::Zero();  // p_DM, always computed
  bool collinear = false;
  std::string failure;  // why ok is false
  // Eq. 4's normal equations A^T A Phi = A^T b at these distances, for the Jacobian (uhl_jacobian).
  Eigen::Matrix2d eq4_ata = Eigen::Matrix2d::Zero();
  Eigen::Vector2d eq4_atb = Eigen::Vector2d::Zero();
};

// Eq. 4-9: the robot's heading; nullopt when A is rank-deficient (fewer than two distinct Txs).
std::optional<double> uhl_orientation(const std::vector<TxDistances>& txs, const UhlOptions& options);
// Eq. 10: the DM position for a known heading; nullopt when G_DM is rank-deficient.
std::optional<Eigen::Vector2d> uhl_direct_position(const std::vector<TxDistances>& txs, double yaw_rad,
                                                   const UhlOptions& options);
// Eq. 11: rho_i, the 3D range from the robot centre to Tx i.
double uhl_centre_range(const TxDistances& tx, const UhlOptions& options);
// Eq. 11-13: the IMR position; for collinear Txs the side of their line closest to p_dm.
std::optional<Eigen::Vector2d> uhl_indirect_position(const std::vector<TxDistances>& txs, bool collinear,
                                                     const Eigen::Vector2d& p_dm, const UhlOptions& options);
// Table I.
UhlSolution solve_uhl(const std::vector<TxDistances>& txs, const UhlOptions& options = {});

// d pose / d [d^1; d^2; ...] (3 x 3N) of a solution of solve_uhl on these txs, analytic, where the pose is
// the DM heading (eq. 4-9) and the IMR multilateration (eq. 11) on non-collinear Txs; nullopt on the other
// branches of Table I (collinear Txs), whose Jacobian is left to numeric differentiation.
using UhlJacobian = Eigen::Matrix<double, 3, Eigen::Dynamic>;
std::optional<UhlJacobian> uhl_jacobian(const std::vector<TxDistances>& txs, const UhlSolution& solution,
                                        const UhlOptions& options = {});
// The same by central differences of solve_uhl, for every branch (6N solves).
UhlJacobian uhl_jacobian_numeric(const std::vector<TxDistances>& txs, const UhlOptions& options = {});

}  // namespace beaconloc::duhl
