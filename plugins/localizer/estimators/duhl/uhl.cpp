#include "uhl.hpp"

#include <Eigen/Eigenvalues>
#include <Eigen/QR>
#include <cmath>

namespace beaconloc::duhl {
namespace {

// The receivers' positions in the robot frame (eq. 1): r_R [cos g_l, sin g_l], g_l = 2 pi (l-1) / 3.
Eigen::Vector2d receiver_base(int l, double r_r) {
  const double g = 2.0 * M_PI * l / 3.0;
  return {r_r * std::cos(g), r_r * std::sin(g)};
}

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

// Eq. 7 as a function of phi, and its derivative.
struct Eq7 {
  double a1, a2, a3, b1, b2;
  double value(double phi) const {
    const double c = std::cos(phi), s = std::sin(phi);
    return a3 * (c * c - s * s) + (a2 - a1) * c * s + b2 * c - b1 * s;
  }
  double derivative(double phi) const {
    const double c = std::cos(phi), s = std::sin(phi);
    return -4.0 * a3 * c * s + (a2 - a1) * (c * c - s * s) - b2 * s - b1 * c;
  }
  double scale() const { return std::abs(a1) + std::abs(a2) + std::abs(a3) + std::abs(b1) + std::abs(b2); }
};

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

}  // namespace

std::optional<double> uhl_orientation(const std::vector<TxDistances>& txs, const UhlOptions& o) {
  // Eq. 4: two rows per pair of Txs.
  const int n = static_cast<int>(txs.size());
  if (n < 2) return std::nullopt;
  Eigen::MatrixXd a(n * (n - 1), 2);
  Eigen::VectorXd b(n * (n - 1));
  const double k = 1.0 / (2.0 * std::sqrt(3.0) * o.receiver_radius_m);
  int row = 0;
  for (int i = 0; i < n; ++i) {
    for (int j = i + 1; j < n; ++j) {
      const Eigen::Vector3d& di = txs[i].distances_m;
      const Eigen::Vector3d& dj = txs[j].distances_m;
      const double dx = txs[j].tx_map_m.x() - txs[i].tx_map_m.x(),
                   dy = txs[j].tx_map_m.y() - txs[i].tx_map_m.y();
      a.row(row) << std::sqrt(3.0) * dx, std::sqrt(3.0) * dy;
      b(row++) = k * (2 * di(0) * di(0) - di(1) * di(1) - di(2) * di(2) - 2 * dj(0) * dj(0) + dj(1) * dj(1) +
                      dj(2) * dj(2));
      a.row(row) << -dy, dx;
      b(row++) = k * (-di(1) * di(1) + di(2) * di(2) + dj(1) * dj(1) - dj(2) * dj(2));
    }
  }
  const Eigen::Matrix2d ata = a.transpose() * a;
  const Eigen::Vector2d atb = a.transpose() * b;
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> check(ata);
  if (!(check.eigenvalues()(0) > 1e-12 * std::max(1.0, check.eigenvalues()(1)))) return std::nullopt;
  const Eigen::Vector2d phi_pinv = ata.ldlt().solve(atb);  // the pseudoinverse solution of eq. 4

  // Eq. 7-8, with A^T A = [[a1, a3], [a3, a2]] and A^T b = -[b1, b2].
  const Eq7 eq7{ata(0, 0), ata(1, 1), ata(0, 1), -atb(0), -atb(1)};
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
        const double phi = std::atan2(s, c);
        // Squaring to reach the quartic adds roots: keep those that satisfy eq. 7 (ERRATA).
        if (std::abs(eq7.value(phi)) > 1e-6 * eq7.scale()) continue;
        const double distance = (Eigen::Vector2d(c, s) - phi_pinv).norm();
        if (distance < best_distance) {
          best_distance = distance;
          best_phi = phi;
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

std::optional<Eigen::Vector2d> uhl_direct_position(const std::vector<TxDistances>& txs, double yaw,
                                                   const UhlOptions& o) {
  // Eq. 10: G_DM [x, y, x^2 + y^2]^T = h_DM, three rows per Tx (ERRATA: every row of h_DM is
  // 0.5 (-(d_l^i)^2 + (x_i - g_l^x)^2 + (y_i - g_l^y)^2 + z_T^2)).
  const int n = static_cast<int>(txs.size());
  Eigen::MatrixXd g(3 * n, 3);
  Eigen::VectorXd h(3 * n);
  const double c = std::cos(yaw), s = std::sin(yaw);
  for (int i = 0; i < n; ++i) {
    const Eigen::Vector3d& t = txs[i].tx_map_m;
    const double z = t.z() - o.receiver_height_m;
    for (int l = 0; l < 3; ++l) {
      const Eigen::Vector2d r = receiver_base(l, o.receiver_radius_m);
      const double gx = r.x() * c - r.y() * s, gy = r.x() * s + r.y() * c;
      const double d = txs[i].distances_m(l);
      g.row(3 * i + l) << t.x() - gx, t.y() - gy, -0.5;
      h(3 * i + l) = 0.5 * (-d * d + (t.x() - gx) * (t.x() - gx) + (t.y() - gy) * (t.y() - gy) + z * z);
    }
  }
  const Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(g);
  if (qr.rank() < 3) return std::nullopt;
  const Eigen::Vector3d theta = qr.solve(h);
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
    Eigen::MatrixXd m(n - 1, 2);
    Eigen::VectorXd v(n - 1);
    const Eigen::Vector2d p0 = txs[0].tx_map_m.head<2>();
    for (int i = 1; i < n; ++i) {
      const Eigen::Vector2d pi = txs[i].tx_map_m.head<2>();
      m.row(i - 1) = 2.0 * (pi - p0).transpose();
      v(i - 1) = r[0] * r[0] - r[i] * r[i] + pi.squaredNorm() - p0.squaredNorm();
    }
    const Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(m);
    if (qr.rank() < 2) return std::nullopt;
    return Eigen::Vector2d(qr.solve(v));
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
  const auto yaw = uhl_orientation(txs, o);  // Table I, line 1
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

}  // namespace beaconloc::duhl
