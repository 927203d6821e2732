#include "beaconloc/core/filters/outcome.hpp"

namespace beaconloc {

const char* to_string(FilterOutcome outcome) {
  switch (outcome) {
    case FilterOutcome::kApplied:
      return "applied";
    case FilterOutcome::kGated:
      return "gated_nis";
    case FilterOutcome::kSingularInnovation:
      return "singular_innovation";
    case FilterOutcome::kNotPositiveDefinite:
      return "covariance_not_positive_definite";
    case FilterOutcome::kBoundNotMet:
      return "h_infinity_bound_not_met";
    case FilterOutcome::kNonFinite:
      return "non_finite_model";
    case FilterOutcome::kSizeMismatch:
      return "size_mismatch";
  }
  return "unknown";
}

}  // namespace beaconloc
