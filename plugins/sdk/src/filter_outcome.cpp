#include "beaconloc/core/filters/outcome.hpp"

#include "beaconloc/core/rejection.hpp"

namespace beaconloc {

const char* to_string(FilterOutcome outcome) {
  return outcome == FilterOutcome::kApplied ? "applied" : to_string(rejection_for(outcome));
}

}  // namespace beaconloc
