#pragma once
// What a filter's predict or update did. Every failure is an outcome: nothing was applied and
// the filter's state and covariance are as they were (never an assert, never a half update).
#include <cstdint>

namespace beaconloc {

enum class FilterOutcome : std::uint8_t {
  kApplied,
  kGated,               // NIS above the gate: the measurement is an outlier for this state
  kSingularInnovation,  // the innovation covariance S is not positive definite
  kNotPositiveDefinite, // the covariance (prior, augmented or posterior) is not positive definite
  kBoundNotMet,         // H-infinity: P^-1 - theta I + H^T R^-1 H is not positive definite
  kNonFinite,           // the model gave a non-finite prediction, Jacobian or noise
  kSizeMismatch,        // z, R or the Jacobian do not have the model's or the state's size
  kStaleSigmaPoints,    // UKF: sigma points drawn for another belief or another R (ukf.hpp)
  kEveryComponentGated, // UKF ComponentGate: every component an outlier on its own, nothing to fuse
};
const char* to_string(FilterOutcome outcome);

struct UpdateResult {
  FilterOutcome outcome = FilterOutcome::kApplied;
  // At the prior, over the components fused (a UKF ComponentGate's gated ones left out):
  double nis = 0.0;    // normalized innovation squared nu^T S^-1 nu
  double log_det_s = 0.0;  // log det S: with nis, the innovation's likelihood
  int iterations = 0;  // linearizations made (1 for the EKF, up to the cap for the IEKF)
  // UKF ComponentGate: components found outliers on their own (left out of the update when it
  // is applied; all of them when the outcome is kEveryComponentGated).
  int components_gated = 0;
  bool applied() const { return outcome == FilterOutcome::kApplied; }
};

struct PredictResult {
  FilterOutcome outcome = FilterOutcome::kApplied;
  bool applied() const { return outcome == FilterOutcome::kApplied; }
};

}  // namespace beaconloc
