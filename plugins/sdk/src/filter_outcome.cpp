#include "beaconloc/core/filters/outcome.hpp"

#include "beaconloc/core/rejection.hpp"

namespace beaconloc {

const char* to_string(FilterOutcome outcome) {
  const std::optional<Rejection> rejection = rejection_for(outcome);
  return rejection ? to_string(*rejection) : "applied";
}

}  // namespace beaconloc
