#pragma once
#include <cmath>

namespace beaconloc {

// Seed 000, Section II-A: c = 20.05 sqrt(T_c + 273.16) m/s for the air temperature T_c in Celsius.
inline double speed_of_sound_mps(double temperature_c) { return 20.05 * std::sqrt(temperature_c + 273.16); }

}  // namespace beaconloc
