#include "number_options.hpp"

#include <limits>
#include <sstream>

#include "beaconloc/core/decimal.hpp"

namespace beaconloc::cli {
namespace {

std::string interval(double min, double max, bool min_open) {
  std::ostringstream s;
  s << (min_open ? "(" : "[") << min << ", " << max << "]";
  return s.str();
}

std::string in_quotes(const std::string& text) { return "'" + text + "'"; }

}  // namespace

CLI::Validator real_in(double min, double max, bool min_open) {
  const std::string range = interval(min, max, min_open);
  return CLI::Validator(
      [=](std::string& text) {
        double v = 0.0;
        const NumberError e = parse_decimal(text, v);
        if (e != NumberError::kNone) return in_quotes(text) + " " + describe(e);
        if (min_open ? !(v > min) : !(v >= min)) return in_quotes(text) + " is outside " + range;
        if (!(v <= max)) return in_quotes(text) + " is outside " + range;
        return std::string();
      },
      "REAL in " + range);
}

CLI::Validator whole_in(std::int64_t min, std::int64_t max) {
  const std::string range = "[" + std::to_string(min) + ", " + std::to_string(max) + "]";
  return CLI::Validator(
      [=](std::string& text) {
        std::int64_t v = 0;
        const NumberError e = parse_decimal(text, v);
        if (e == NumberError::kNotDecimal) return in_quotes(text) + " is not a whole decimal number";
        if (e == NumberError::kOutOfRange || v < min || v > max)
          return in_quotes(text) + " is outside " + range;
        text = std::to_string(v);  // CLI11 reads "010" as octal
        return std::string();
      },
      "INT in " + range);
}

CLI::Validator any_unsigned() {
  return CLI::Validator(
      [](std::string& text) {
        std::uint64_t v = 0;
        const NumberError e = parse_decimal(text, v);
        if (e == NumberError::kNotDecimal) return in_quotes(text) + " is not a whole decimal number";
        if (e == NumberError::kOutOfRange)
          return in_quotes(text) + " is outside [0, " +
                 std::to_string(std::numeric_limits<std::uint64_t>::max()) + "]";
        text = std::to_string(v);
        return std::string();
      },
      "UINT");
}

}  // namespace beaconloc::cli
