#pragma once
// The one parser of every number the project reads from a file (CSV cells, YAML scalars, PGM
// headers and pixels) or an option (--param, --receivers, --fault and every numeric option).
// Numbers are decimal: an optional sign, digits with an optional fraction, an optional exponent
// ("12", "-0.5", ".25", "+2", "1e-3"). Refused, as kNotDecimal: an empty text, whitespace before,
// inside or after it, anything after the number, hexadecimal ("0x10", "0x1p1"), "inf", "nan";
// for an integer also a fraction or an exponent. Refused as kOutOfRange: a value the type cannot
// hold ("1e400", "1e-400" for a double, "-1" for an unsigned). No format the project reads
// documents a non-finite number, so a parsed double is always finite.
#include <cstdint>
#include <string>
#include <string_view>

namespace beaconloc {

enum class NumberError { kNone, kNotDecimal, kOutOfRange };
// "is not a decimal number", "is out of range" (empty for kNone): messages read
// "<field> '<text>' <describe(e)>".
const char* describe(NumberError e);

NumberError parse_decimal(std::string_view text, double& out);
NumberError parse_decimal(std::string_view text, std::int64_t& out);
NumberError parse_decimal(std::string_view text, std::uint64_t& out);
NumberError parse_decimal(std::string_view text, std::int32_t& out);
NumberError parse_decimal(std::string_view text, std::uint32_t& out);

// "<what> '<text>' is not a decimal number" (or "is out of range"), for messages.
std::string number_problem(const std::string& what, std::string_view text, NumberError e);
// "<what> <value> is outside [min, max]": a number that parsed but lies beyond its field's range.
std::string range_problem(const std::string& what, double value, double min, double max);

// Appends the shortest decimal text that parse_decimal reads back to exactly this finite double
// (std::to_chars; it may use an exponent, "1e-07"): files the project writes to be read again
// (beacon maps, recordings of the bus) lose nothing.
void append_decimal(std::string& out, double value);

// The value of text, or std::invalid_argument(number_problem(what, text, ...)).
double decimal_or_throw(std::string_view text, const std::string& what);

}  // namespace beaconloc
