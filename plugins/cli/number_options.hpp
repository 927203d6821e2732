#pragma once
// The validators of every numeric command-line option, defined once. CLI11 alone reads "0x10"
// as 16 and "010" as 8, takes "0x1p1" and "inf", and wraps "--seed -1" into 2^64 - 1; here the
// text must be a decimal number (core/decimal.hpp) within the option's range, and CLI11 names
// the option in the error: "--max-age-ms: '1e300' is outside (0, 60000]". Attach with
// ->transform(...): a whole number's text is rewritten in plain decimal before CLI11 converts it.
#include <CLI/CLI.hpp>
#include <cstdint>

namespace beaconloc::cli {

// A real number in [min, max]; with min_open, in (min, max].
CLI::Validator real_in(double min, double max, bool min_open = false);
// A whole number in [min, max].
CLI::Validator whole_in(std::int64_t min, std::int64_t max);
// A whole number in [0, 2^64 - 1] (seeds).
CLI::Validator any_unsigned();

}  // namespace beaconloc::cli
