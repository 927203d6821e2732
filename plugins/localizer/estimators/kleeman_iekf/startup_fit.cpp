#include "kleeman_iekf/startup_fit.hpp"

#include <Eigen/Cholesky>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>
#include <set>

namespace beaconloc::kleeman {

namespace {

using Params = Vec<6>;
using P = StartupFit::Parameter;
constexpr Eigen::Index idx(P p) { return static_cast<Eigen::Index>(p); }

// The weak prior on theta: 10 rad, so that a robot standing still keeps its guess rather than
// leaving the normal equations singular; the fit's heading variance then says it is unknown.
constexpr double kHeadingPriorSigmaRad = 10.0;
constexpr int kMaxIterations = 30;

struct Observation {
  SlotPulse pulse;
  double forward_m = 0.0;  // displacement since the reference, robot frame at the reference
  double left_m = 0.0;
};

struct Problem {
  std::vector<Observation> obs;
  std::int64_t first_slot = 0;
  const StartupFitSettings* settings = nullptr;
  double heading_prior_rad = 0.0;
};

// Residual of each observation (a - prediction) and its gradient.
double residual(const Problem& pb, const Observation& o, const Params& x, Vec<6>* gradient) {
  const double c = std::cos(x(idx(P::kHeading))), s = std::sin(x(idx(P::kHeading)));
  const Eigen::Vector3d robot(x(idx(P::kX)) + c * o.forward_m - s * o.left_m,
                              x(idx(P::kY)) + s * o.forward_m + c * o.left_m, pb.settings->receiver_z_m);
  const Eigen::Vector3d delta = robot - o.pulse.beacon_map_m;
  const double d = delta.norm();
  const double sos = x(idx(P::kSpeedOfSound));
  const double slots = static_cast<double>(o.pulse.slot - pb.first_slot);
  const double predicted = x(idx(P::kFirstFireTime)) + slots * x(idx(P::kCycle)) + d / sos;
  if (gradient) {
    const Eigen::Vector3d u = d > 0.0 ? Eigen::Vector3d(delta / d) : Eigen::Vector3d::Zero();
    Vec<6>& g = *gradient;  // of the prediction
    g(idx(P::kX)) = u.x() / sos;
    g(idx(P::kY)) = u.y() / sos;
    g(idx(P::kHeading)) = (u.x() * (-s * o.forward_m - c * o.left_m) + u.y() * (c * o.forward_m - s * o.left_m)) / sos;
    g(idx(P::kFirstFireTime)) = 1.0;
    g(idx(P::kCycle)) = slots;
    g(idx(P::kSpeedOfSound)) = -d / (sos * sos);
  }
  return o.pulse.arrival_s - predicted;
}

struct Priors {
  Params mean = Params::Zero();
  Params information = Params::Zero();  // 1 / sigma^2, 0 where none
};

Priors priors_of(const Problem& pb) {
  const StartupFitSettings& st = *pb.settings;
  Priors p;
  p.mean(idx(P::kHeading)) = pb.heading_prior_rad;
  p.information(idx(P::kHeading)) = 1.0 / (kHeadingPriorSigmaRad * kHeadingPriorSigmaRad);
  p.mean(idx(P::kCycle)) = st.cycle_s;
  p.information(idx(P::kCycle)) = 1.0 / (st.cycle_sigma_s * st.cycle_sigma_s);
  p.mean(idx(P::kSpeedOfSound)) = st.speed_of_sound_mps;
  p.information(idx(P::kSpeedOfSound)) = 1.0 / (st.speed_of_sound_sigma_mps * st.speed_of_sound_sigma_mps);
  return p;
}

double cost(const Problem& pb, const Priors& priors, const Params& x) {
  const double w = 1.0 / (pb.settings->arrival_sigma_s * pb.settings->arrival_sigma_s);
  double c = 0.0;
  for (const Observation& o : pb.obs) {
    const double r = residual(pb, o, x, nullptr);
    c += w * r * r;
  }
  Params d = x - priors.mean;
  d(idx(P::kHeading)) = wrap_angle_rad(d(idx(P::kHeading)));
  return c + d.cwiseProduct(d).dot(priors.information);
}

// Gauss-Newton with step halving; the information matrix at the solution in `information`.
// Returns the cost, or +inf when the normal equations cannot be solved.
double solve(const Problem& pb, Params& x, Mat<6, 6>* information) {
  const Priors priors = priors_of(pb);
  const double w = 1.0 / (pb.settings->arrival_sigma_s * pb.settings->arrival_sigma_s);
  double current = cost(pb, priors, x);
  Mat<6, 6> a;
  for (int it = 0; it < kMaxIterations; ++it) {
    a = priors.information.asDiagonal();
    Params b = Params::Zero();
    Params d = priors.mean - x;
    d(idx(P::kHeading)) = wrap_angle_rad(d(idx(P::kHeading)));
    b = priors.information.cwiseProduct(d);
    for (const Observation& o : pb.obs) {
      Vec<6> g;
      const double r = residual(pb, o, x, &g);
      a.noalias() += w * g * g.transpose();
      b += w * g * r;
    }
    const Eigen::LDLT<Mat<6, 6>> ldlt(a);
    if (ldlt.info() != Eigen::Success || !(ldlt.vectorD().array() > 0.0).all()) return std::numeric_limits<double>::infinity();
    const Params step = ldlt.solve(b);
    if (!step.allFinite()) return std::numeric_limits<double>::infinity();
    double scale = 1.0, next = current;
    Params trial = x;
    for (int halving = 0; halving < 20; ++halving) {
      trial = x + scale * step;
      next = cost(pb, priors, trial);
      if (next <= current) break;
      scale *= 0.5;
    }
    if (!(next <= current)) break;  // no step decreases the cost: at the minimum
    const bool converged = current - next <= 1e-9 * (1.0 + current);
    x = trial;
    current = next;
    if (converged) break;
  }
  if (information) {
    a = priors.information.asDiagonal();
    for (const Observation& o : pb.obs) {
      Vec<6> g;
      residual(pb, o, x, &g);
      a.noalias() += w * g * g.transpose();
    }
    *information = a;
  }
  return current;
}

// t_first for a position and heading: the mean of what each pulse says, with the nominal T and s.
double first_fire_time(const Problem& pb, const Params& x) {
  double sum = 0.0;
  Params at = x;
  at(idx(P::kFirstFireTime)) = 0.0;
  for (const Observation& o : pb.obs) sum += residual(pb, o, at, nullptr);
  return sum / static_cast<double>(pb.obs.size());
}

}  // namespace

StartupFit fit_startup(const std::vector<SlotPulse>& pulses, const OdometryTrack* track,
                       const StartupFitSettings& settings, double heading_guess_rad) {
  StartupFit fit;
  if (pulses.empty()) {
    fit.why_not = "no pulses";
    return fit;
  }
  Problem pb;
  pb.settings = &settings;
  pb.heading_prior_rad = heading_guess_rad;
  pb.first_slot = pulses.front().slot;
  fit.reference_s = pulses.front().arrival_s;
  double moved_m = 0.0;
  Eigen::AlignedBox2d extent;
  for (const SlotPulse& p : pulses) {
    Observation o;
    o.pulse = p;
    if (track) {
      const DeadReckoning d = track->between(fit.reference_s, p.arrival_s);
      o.forward_m = d.forward_m;
      o.left_m = d.left_m;
    }
    moved_m = std::max(moved_m, std::hypot(o.forward_m, o.left_m));
    extent.extend(p.beacon_map_m.head<2>());
    pb.first_slot = std::min(pb.first_slot, p.slot);
    pb.obs.push_back(o);
  }
  fit.first_slot = pb.first_slot;
  fit.heading_observed = moved_m >= settings.heading_observed_after_m;

  // Starts: a 3 x 3 grid over the beacons' extent (and four headings once the robot moved).
  std::vector<double> headings{heading_guess_rad};
  if (fit.heading_observed) {
    for (int k = 1; k < 4; ++k) headings.push_back(wrap_angle_rad(heading_guess_rad + k * M_PI / 2.0));
  }
  double best_cost = std::numeric_limits<double>::infinity();
  Params best = Params::Zero();
  for (int ix = 0; ix < 3; ++ix) {
    for (int iy = 0; iy < 3; ++iy) {
      for (const double heading : headings) {
        Params x = Params::Zero();
        x(idx(P::kX)) = extent.min().x() + (0.5 * ix) * extent.sizes().x();
        x(idx(P::kY)) = extent.min().y() + (0.5 * iy) * extent.sizes().y();
        x(idx(P::kHeading)) = heading;
        x(idx(P::kCycle)) = settings.cycle_s;
        x(idx(P::kSpeedOfSound)) = settings.speed_of_sound_mps;
        x(idx(P::kFirstFireTime)) = first_fire_time(pb, x);
        const double c = solve(pb, x, nullptr);
        if (c < best_cost) {
          best_cost = c;
          best = x;
        }
      }
    }
  }
  if (!std::isfinite(best_cost)) {
    fit.why_not = "the arrival times leave the fit singular";
    return fit;
  }
  // Drop the worst pulse while it misses by more than the gate (an echo), and refit.
  Mat<6, 6> information;
  for (;;) {
    if (!std::isfinite(solve(pb, best, &information))) {
      fit.why_not = "the arrival times leave the fit singular";
      return fit;
    }
    std::size_t worst = 0;
    double worst_abs = 0.0;
    for (std::size_t i = 0; i < pb.obs.size(); ++i) {
      const double r = std::abs(residual(pb, pb.obs[i], best, nullptr));
      if (r > worst_abs) {
        worst_abs = r;
        worst = i;
      }
    }
    if (worst_abs <= settings.outlier_gate_s) break;
    if (static_cast<int>(pb.obs.size()) <= settings.min_pulses) {
      fit.why_not = "too many pulses miss the fit (echoes, or a numbering the pulses contradict)";
      return fit;
    }
    pb.obs.erase(pb.obs.begin() + static_cast<std::ptrdiff_t>(worst));
    ++fit.pulses_dropped;
  }
  std::set<std::uint32_t> beacons;
  double sum2 = 0.0;
  for (const Observation& o : pb.obs) {
    beacons.insert(o.pulse.beacon_id);
    const double r = residual(pb, o, best, nullptr);
    sum2 += r * r;
  }
  fit.pulses_used = static_cast<int>(pb.obs.size());
  fit.rms_residual_s = std::sqrt(sum2 / static_cast<double>(pb.obs.size()));
  if (fit.pulses_used < settings.min_pulses || static_cast<int>(beacons.size()) < settings.min_beacons) {
    fit.why_not = "too few pulses or beacons left: " + std::to_string(fit.pulses_used) + " pulses from " +
                  std::to_string(beacons.size()) + " beacons";
    return fit;
  }
  const Eigen::LDLT<Mat<6, 6>> ldlt(information);
  if (ldlt.info() != Eigen::Success || !(ldlt.vectorD().array() > 0.0).all()) {
    fit.why_not = "the fit's information is singular";
    return fit;
  }
  fit.covariance = ldlt.solve(Mat<6, 6>::Identity());
  fit.covariance = 0.5 * (fit.covariance + fit.covariance.transpose()).eval();
  best(idx(P::kHeading)) = wrap_angle_rad(best(idx(P::kHeading)));
  fit.solution = best;
  fit.ok = fit.solution.allFinite() && fit.covariance.allFinite();
  if (!fit.ok) fit.why_not = "the fit is not finite";
  return fit;
}

}  // namespace beaconloc::kleeman
