#include "uhl.hpp"

#include <Eigen/Eigenvalues>
#include <Eigen/QR>
#include <array>
#include <cmath>

#include "distance_prediction.hpp"

namespace beaconloc::duhl {
namespace {

// The receivers' positions in the robot frame (eq. 1): r_R [cos g_l, sin g_l], g_l = 2 pi (l-1) / 3
// (the ring the distance prediction uses too, its cosines and sines computed once).
Eigen::Vector2d receiver_base(int l, double r_r) { return ReceiverRing{r_r, 0.0}.receiver(l); }

// The line l_T through the Txs (principal axis of their planar positions): centroid, unit
// normal, and the RMS spread across it.
struct TxLine {
  Eigen::Vector2d centroid;
  Eigen::Vector2d normal;  // [xi_a, xi_b] of eq. 13, xi_a^2 + xi_b^2 = 1
  double spread_m;
  double signed_distance(const Eigen::Vector2d& p) const {
    return normal.dot(p - centroid);
  }  // Delta, eq. 13
};

TxLine tx_line(const std::vector<TxDistances>& txs) {
  TxLine line;
  line.centroid = Eigen::Vector2d::Zero();
  for (const auto& t : txs) line.centroid += t.tx_map_m.head<2>();
  line.centroid /= static_cast<double>(txs.size());
  Eigen::Matrix2d scatter = Eigen::Matrix2d::Zero();
  for (const auto& t : txs) {
    const Eigen::Vector2d d = t.tx_map_m.head<2>() - line.centroid;
    scatter += d * d.transpose() / static_cast<double>(txs.size());
  }
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> eig(scatter);
  line.normal = eig.eigenvectors().col(0);  // smallest eigenvalue: across the line
  line.spread_m = std::sqrt(std::max(0.0, eig.eigenvalues()(0)));
  return line;
}

// A symmetric positive semi-definite normal matrix is usable when its smallest eigenvalue is not
// lost in rounding against its largest.
template <int N>
bool well_conditioned(const Eigen::Matrix<double, N, N>& normal) {
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, N, N>> eig;
  eig.computeDirect(normal, Eigen::EigenvaluesOnly);
  return eig.eigenvalues()(0) > 1e-12 * std::max(1.0, eig.eigenvalues()(N - 1));
}

// The two rows of eq. 4 for Txs i and j: A^{i,j} Phi = b^{i,j} (ERRATA).
struct EqFourRows {
  Eigen::Matrix2d a;
  Eigen::Vector2d b;
};

double eq_four_k(double r_r) { return 1.0 / (2.0 * std::sqrt(3.0) * r_r); }

// A^{i,j} of eq. 4 from the Tx offset [dx, dy] = p_j - p_i (linear in it).
Eigen::Matrix2d eq_four_rows_of(const Eigen::Vector2d& offset) {
  Eigen::Matrix2d a;
  a << std::sqrt(3.0) * offset.x(), std::sqrt(3.0) * offset.y(), -offset.y(), offset.x();
  return a;
}

EqFourRows eq_four_rows(const TxDistances& ti, const TxDistances& tj, double r_r) {
  const Eigen::Vector3d& di = ti.distances_m;
  const Eigen::Vector3d& dj = tj.distances_m;
  const double k = eq_four_k(r_r);
  const double dx = tj.tx_map_m.x() - ti.tx_map_m.x(), dy = tj.tx_map_m.y() - ti.tx_map_m.y();
  EqFourRows rows;
  rows.a = eq_four_rows_of({dx, dy});
  rows.b << k * (2 * di(0) * di(0) - di(1) * di(1) - di(2) * di(2) - 2 * dj(0) * dj(0) + dj(1) * dj(1) +
                 dj(2) * dj(2)),
      k * (-di(1) * di(1) + di(2) * di(2) + dj(1) * dj(1) - dj(2) * dj(2));
  return rows;
}

// d b^{i,j} / d d^i; d b^{i,j} / d d^j is its negative evaluated at d^j.
Eigen::Matrix<double, 2, 3> eq_four_gradient(const Eigen::Vector3d& d, double r_r) {
  const double k = eq_four_k(r_r);
  Eigen::Matrix<double, 2, 3> g;
  g << 4 * k * d(0), -2 * k * d(1), -2 * k * d(2), 0.0, -2 * k * d(1), 2 * k * d(2);
  return g;
}

// Eq. 4 for every pair of Txs, accumulated straight into the normal equations A^T A Phi = A^T b.
struct EqFourNormal {
  Eigen::Matrix2d ata = Eigen::Matrix2d::Zero();
  Eigen::Vector2d atb = Eigen::Vector2d::Zero();
};

EqFourNormal eq_four_normal(const std::vector<TxDistances>& txs, double r_r) {
  EqFourNormal out;
  const std::size_t n = txs.size();
  for (std::size_t i = 0; i < n; ++i) {
    for (std::size_t j = i + 1; j < n; ++j) {
      const EqFourRows rows = eq_four_rows(txs[i], txs[j], r_r);
      out.ata += rows.a.transpose() * rows.a;
      out.atb += rows.a.transpose() * rows.b;
    }
  }
  return out;
}

// Eq. 7 as a function of phi, and its derivative.
struct Eq7 {
  double a1, a2, a3, b1, b2;
  double value(double phi) const { return value(std::cos(phi), std::sin(phi)); }
  // The same at [cos phi, sin phi] = [c, s].
  double value(double c, double s) const {
    return a3 * (c * c - s * s) + (a2 - a1) * c * s + b2 * c - b1 * s;
  }
  double derivative(double phi) const {
    const double c = std::cos(phi), s = std::sin(phi);
    return -4.0 * a3 * c * s + (a2 - a1) * (c * c - s * s) - b2 * s - b1 * c;
  }
  double scale() const { return std::abs(a1) + std::abs(a2) + std::abs(a3) + std::abs(b1) + std::abs(b2); }
};

// Eq. 7-8, with A^T A = [[a1, a3], [a3, a2]] and A^T b = -[b1, b2].
Eq7 eq7_of(const Eigen::Matrix2d& ata, const Eigen::Vector2d& atb) {
  return {ata(0, 0), ata(1, 1), ata(0, 1), -atb(0), -atb(1)};
}

// Real roots of k4 s^4 + k3 s^3 + k2 s^2 + k1 s + k0 (eigenvalues of the companion matrix).
std::vector<double> real_quartic_roots(double k4, double k3, double k2, double k1, double k0) {
  std::vector<double> roots;
  Eigen::Matrix4d companion = Eigen::Matrix4d::Zero();
  companion(0, 0) = -k3 / k4;
  companion(0, 1) = -k2 / k4;
  companion(0, 2) = -k1 / k4;
  companion(0, 3) = -k0 / k4;
  companion(1, 0) = companion(2, 1) = companion(3, 2) = 1.0;
  const Eigen::EigenSolver<Eigen::Matrix4d> eig(companion, false);
  for (int i = 0; i < 4; ++i) {
    const std::complex<double> r = eig.eigenvalues()(i);
    if (std::abs(r.imag()) <= 1e-7 * (1.0 + std::abs(r.real()))) roots.push_back(r.real());
  }
  return roots;
}

// Eq. 5-9 on eq. 4's normal equations.
std::optional<double> orientation_from(const EqFourNormal& normal) {
  const Eigen::Matrix2d& ata = normal.ata;
  const Eigen::Vector2d& atb = normal.atb;
  if (!well_conditioned(ata)) return std::nullopt;
  const Eigen::Vector2d phi_pinv = ata.ldlt().solve(atb);  // the pseudoinverse solution of eq. 4

  const Eq7 eq7 = eq7_of(ata, atb);
  const double d = eq7.a1 - eq7.a2;
  const double k4 = d * d + 4 * eq7.a3 * eq7.a3;
  const double k3 = -2 * d * eq7.b2 + 4 * eq7.a3 * eq7.b1;
  const double k2 = eq7.b1 * eq7.b1 + eq7.b2 * eq7.b2 - k4;
  const double k1 = 2 * d * eq7.b2 - 2 * eq7.a3 * eq7.b1;
  const double k0 = eq7.a3 * eq7.a3 - eq7.b2 * eq7.b2;
  double best_phi = std::atan2(phi_pinv.y(), phi_pinv.x());
  double best_distance = std::numeric_limits<double>::infinity();
  if (k4 > 1e-12 * eq7.scale() * eq7.scale()) {
    for (double s : real_quartic_roots(k4, k3, k2, k1, k0)) {
      if (std::abs(s) > 1.0 + 1e-6) continue;
      s = std::clamp(s, -1.0, 1.0);
      for (double sign : {1.0, -1.0}) {  // eq. 9: cos = +-sqrt(1 - sin^2), up to eight candidates
        const double c = sign * std::sqrt(1.0 - s * s);
        // Squaring to reach the quartic adds roots: keep those that satisfy eq. 7 (ERRATA),
        // evaluated at [c, s] itself (the angle is needed only for the one kept).
        if (std::abs(eq7.value(c, s)) > 1e-6 * eq7.scale()) continue;
        const double distance = (Eigen::Vector2d(c, s) - phi_pinv).norm();
        if (distance < best_distance) {
          best_distance = distance;
          best_phi = std::atan2(s, c);
        }
      }
    }
  }
  // The root as the companion matrix gives it carries its rounding: polish it on eq. 7.
  for (int it = 0; it < 3 && std::isfinite(best_distance); ++it) {
    const double slope = eq7.derivative(best_phi);
    if (std::abs(slope) < 1e-12 * eq7.scale()) break;
    best_phi -= eq7.value(best_phi) / slope;
  }
  return wrap_angle_rad(best_phi);
}

}  // namespace

std::optional<double> uhl_orientation(const std::vector<TxDistances>& txs, const UhlOptions& o) {
  // Eq. 4: two rows per pair of Txs.
  if (txs.size() < 2) return std::nullopt;
  return orientation_from(eq_four_normal(txs, o.receiver_radius_m));
}

std::optional<Eigen::Vector2d> uhl_direct_position(const std::vector<TxDistances>& txs, double yaw,
                                                   const UhlOptions& o) {
  // Eq. 10: G_DM [x, y, x^2 + y^2]^T = h_DM, three rows per Tx (ERRATA: every row of h_DM is
  // 0.5 (-(d_l^i)^2 + (x_i - g_l^x)^2 + (y_i - g_l^y)^2 + z_T^2)).
  // Accumulated as the normal equations G^T G theta = G^T h (3 x 3), checked for rank.
  const int n = static_cast<int>(txs.size());
  Eigen::Matrix3d gtg = Eigen::Matrix3d::Zero();
  Eigen::Vector3d gth = Eigen::Vector3d::Zero();
  const double c = std::cos(yaw), s = std::sin(yaw);
  // g_l: the receivers rotated by the heading, the same for every Tx.
  std::array<Eigen::Vector2d, 3> g;
  for (int l = 0; l < 3; ++l) {
    const Eigen::Vector2d r = receiver_base(l, o.receiver_radius_m);
    g[l] = {r.x() * c - r.y() * s, r.x() * s + r.y() * c};
  }
  for (int i = 0; i < n; ++i) {
    const Eigen::Vector3d& t = txs[i].tx_map_m;
    const double z = t.z() - o.receiver_height_m;
    for (int l = 0; l < 3; ++l) {
      const double gx = g[l].x(), gy = g[l].y();
      const double d = txs[i].distances_m(l);
      const Eigen::Vector3d row(t.x() - gx, t.y() - gy, -0.5);
      gtg += row * row.transpose();
      gth += row * (0.5 * (-d * d + (t.x() - gx) * (t.x() - gx) + (t.y() - gy) * (t.y() - gy) + z * z));
    }
  }
  if (!well_conditioned(gtg)) return std::nullopt;
  const Eigen::Vector3d theta = gtg.ldlt().solve(gth);
  return Eigen::Vector2d(theta.x(), theta.y());
}

double uhl_centre_range(const TxDistances& tx, const UhlOptions& o) {
  // Eq. 11, isotropic array: rho^2 = mean_l (d_l)^2 - r_R^2 (ERRATA).
  const double mean_sq = tx.distances_m.squaredNorm() / 3.0;
  return std::sqrt(std::max(0.0, mean_sq - o.receiver_radius_m * o.receiver_radius_m));
}

std::optional<Eigen::Vector2d> uhl_indirect_position(const std::vector<TxDistances>& txs, bool collinear,
                                                     const Eigen::Vector2d& p_dm, const UhlOptions& o) {
  const int n = static_cast<int>(txs.size());
  // Radii of the circles on the robot's plane (all Txs at the ceiling height, eq. 11).
  std::vector<double> r(n);
  for (int i = 0; i < n; ++i) {
    const double z = txs[i].tx_map_m.z() - o.receiver_height_m;
    r[i] = std::sqrt(std::max(0.0, std::pow(uhl_centre_range(txs[i], o), 2) - z * z));
  }
  if (!collinear) {
    // Multilateration: differences of the circle equations against Tx 0, least squares.
    if (n < 3) return std::nullopt;
    // Normal equations M^T M p = M^T v (2 x 2), checked for rank.
    Eigen::Matrix2d mtm = Eigen::Matrix2d::Zero();
    Eigen::Vector2d mtv = Eigen::Vector2d::Zero();
    const Eigen::Vector2d p0 = txs[0].tx_map_m.head<2>();
    for (int i = 1; i < n; ++i) {
      const Eigen::Vector2d pi = txs[i].tx_map_m.head<2>();
      const Eigen::Vector2d row = 2.0 * (pi - p0);
      mtm += row * row.transpose();
      mtv += row * (r[0] * r[0] - r[i] * r[i] + pi.squaredNorm() - p0.squaredNorm());
    }
    if (!well_conditioned(mtm)) return std::nullopt;
    return Eigen::Vector2d(mtm.ldlt().solve(mtv));
  }
  // Collinear Txs (eq. 12-13): intersections of every pair of circles, split by the side of the
  // Tx line, averaged per side; the side closer to the DM position wins.
  const TxLine line = tx_line(txs);
  Eigen::Vector2d sum[2] = {Eigen::Vector2d::Zero(), Eigen::Vector2d::Zero()};
  int count[2] = {0, 0};
  for (int i = 0; i < n; ++i) {
    for (int j = i + 1; j < n; ++j) {
      const Eigen::Vector2d ci = txs[i].tx_map_m.head<2>(), cj = txs[j].tx_map_m.head<2>();
      const double d = (cj - ci).norm();
      if (d < 1e-9 || d > r[i] + r[j] || d < std::abs(r[i] - r[j])) continue;  // C = {} (eq. 12)
      const Eigen::Vector2d u = (cj - ci) / d, perp(-u.y(), u.x());
      const double along = (r[i] * r[i] - r[j] * r[j] + d * d) / (2.0 * d);
      const double across = std::sqrt(std::max(0.0, r[i] * r[i] - along * along));
      for (double sign : {1.0, -1.0}) {
        const Eigen::Vector2d point = ci + along * u + sign * across * perp;
        const double delta = line.signed_distance(point);  // Delta_k^{i,j}, eq. 13
        if (delta >= 0.0) {
          sum[0] += point;
          ++count[0];
        }
        if (delta <= 0.0) {
          sum[1] += point;
          ++count[1];
        }
        if (across == 0.0) break;  // one intersection
      }
    }
  }
  std::optional<Eigen::Vector2d> best;
  for (int side = 0; side < 2; ++side) {
    if (!count[side]) continue;
    const Eigen::Vector2d estimate = sum[side] / count[side];
    if (!best || (estimate - p_dm).norm() < (*best - p_dm).norm()) best = estimate;
  }
  return best;
}

UhlSolution solve_uhl(const std::vector<TxDistances>& txs, const UhlOptions& o) {
  UhlSolution out;
  if (txs.size() < 2) {
    out.failure = "too_few_txs";
    return out;
  }
  for (const auto& t : txs) {
    if (!t.tx_map_m.allFinite() || !t.distances_m.allFinite() || (t.distances_m.array() <= 0.0).any()) {
      out.failure = "invalid_distances";
      return out;
    }
  }
  const EqFourNormal normal = eq_four_normal(txs, o.receiver_radius_m);
  out.eq4_ata = normal.ata;
  out.eq4_atb = normal.atb;
  const auto yaw = orientation_from(normal);  // Table I, line 1
  if (!yaw) {
    out.failure = "orientation_unobservable";
    return out;
  }
  const auto p_dm = uhl_direct_position(txs, *yaw, o);  // line 2
  if (!p_dm) {
    out.failure = "position_unobservable";
    return out;
  }
  out.direct_position_m = *p_dm;
  const TxLine line = tx_line(txs);
  out.collinear = line.spread_m < o.collinearity_tolerance_m;
  out.pose = Pose2(p_dm->x(), p_dm->y(), *yaw);
  out.ok = true;
  if (out.collinear && std::abs(line.signed_distance(*p_dm)) < o.collinear_threshold_m) {
    out.method = UhlMethod::kDirect;  // lines 3-4
    return out;
  }
  // Lines 5-7. Where the IMR has no answer (no circles meet under noise), the DM position stands:
  // Table I does not say; keeping a pose beats having none.
  if (const auto p_imr = uhl_indirect_position(txs, out.collinear, *p_dm, o)) {
    out.pose.head<2>() = *p_imr;
    out.method = UhlMethod::kIndirect;
  }
  return out;
}

std::optional<UhlJacobian> uhl_jacobian(const std::vector<TxDistances>& txs, const UhlSolution& solution,
                                        const UhlOptions& o) {
  if (!solution.ok || solution.method != UhlMethod::kIndirect || solution.collinear) return std::nullopt;
  const int n = static_cast<int>(txs.size());
  UhlJacobian j = UhlJacobian::Zero(3, 3 * n);

  // Heading: the DM's phi solves eq. 7, E(phi, A^T b) = 0 (A does not depend on the distances),
  // so d phi / d q = -(dE / d(A^T b)) (d(A^T b) / d q) / (dE / d phi), with dE / d(A^T b) =
  // [sin phi, -cos phi] from A^T b = -[b1, b2].
  // d(A^T b) / d d^a = S_a db/dd(d^a) (eq_four_gradient), S_a the sum over the pairs (a, b > a)
  // of A^{a,b}^T minus that over the pairs (b < a, a). A^{a,b} is linear in the Tx offset
  // p_b - p_a (eq_four_rows), so S_a = sum over b != a of A(p_b - p_a)^T = A(P - n p_a)^T, P the
  // sum of the Tx positions: one term per Tx instead of one per pair.
  // A^T A and A^T b are the solution's own (solve_uhl keeps them).
  Eigen::Vector2d p_sum = Eigen::Vector2d::Zero();
  for (const auto& t : txs) p_sum += t.tx_map_m.head<2>();
  const double phi = solution.pose.z();
  const Eq7 eq7 = eq7_of(solution.eq4_ata, solution.eq4_atb);
  const double slope = eq7.derivative(phi);
  if (!(std::abs(slope) > 1e-12 * eq7.scale())) return std::nullopt;
  const Eigen::RowVector2d de_datb(std::sin(phi), -std::cos(phi));
  for (int a = 0; a < n; ++a) {
    const Eigen::Vector2d offset = p_sum - n * txs[a].tx_map_m.head<2>();
    const Eigen::Matrix2d s_a = eq_four_rows_of(offset).transpose();
    j.block<1, 3>(2, 3 * a) =
        -(de_datb * s_a * eq_four_gradient(txs[a].distances_m, o.receiver_radius_m)) / slope;
  }

  // Position: the IMR multilateration p = (M^T M)^-1 M^T v, M fixed by the Tx positions and
  // v_i = r_0^2 - r_i^2 + const with r_i^2 = |d^i|^2 / 3 - r_R^2 - z_i^2 (eq. 11). With m_i the
  // row of M for Tx i and w_i = (M^T M)^-1 m_i: d p / d d^i = -(2/3) w_i d^i^T (i >= 1) and
  // d p / d d^0 = (2/3) (sum_i w_i) d^0^T.
  Eigen::Matrix2d mtm = Eigen::Matrix2d::Zero();
  const Eigen::Vector2d p0 = txs[0].tx_map_m.head<2>();
  for (int i = 1; i < n; ++i) {
    const Eigen::Vector2d row = 2.0 * (txs[i].tx_map_m.head<2>() - p0);
    mtm += row * row.transpose();
  }
  if (!well_conditioned(mtm)) return std::nullopt;
  const Eigen::LDLT<Eigen::Matrix2d> ldlt(mtm);
  Eigen::Vector2d w_sum = Eigen::Vector2d::Zero();
  for (int i = 1; i < n; ++i) {
    const Eigen::Vector2d w = ldlt.solve(Eigen::Vector2d(2.0 * (txs[i].tx_map_m.head<2>() - p0)));
    w_sum += w;
    j.block<2, 3>(0, 3 * i) = -(2.0 / 3.0) * w * txs[i].distances_m.transpose();
  }
  j.block<2, 3>(0, 0) = (2.0 / 3.0) * w_sum * txs[0].distances_m.transpose();
  return j;
}

UhlJacobian uhl_jacobian_numeric(const std::vector<TxDistances>& txs, const UhlOptions& options) {
  const double h = 1e-4;  // m: well above rounding, well below the distances' noise
  UhlJacobian j = UhlJacobian::Zero(3, 3 * static_cast<Eigen::Index>(txs.size()));
  for (std::size_t i = 0; i < txs.size(); ++i) {
    for (int l = 0; l < 3; ++l) {
      auto hi = txs, lo = txs;
      hi[i].distances_m(l) += h;
      lo[i].distances_m(l) -= h;
      const UhlSolution a = solve_uhl(hi, options), b = solve_uhl(lo, options);
      if (a.ok && b.ok)
        j.col(3 * static_cast<Eigen::Index>(i) + l) = pose_difference(a.pose, b.pose) / (2 * h);
    }
  }
  return j;
}

}  // namespace beaconloc::duhl
