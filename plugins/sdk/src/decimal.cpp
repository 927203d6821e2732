#include "beaconloc/core/decimal.hpp"

#include <cctype>
#include <charconv>
#include <cmath>
#include <sstream>
#include <stdexcept>
#include <type_traits>

namespace beaconloc {
namespace {

bool is_digit(char c) { return c >= '0' && c <= '9'; }

// Drops one leading '+' (std::from_chars takes only '-'): "+-1" and "+" stay refused.
std::string_view without_plus(std::string_view text) {
  if (text.size() > 1 && text[0] == '+' && text[1] != '-' && text[1] != '+') text.remove_prefix(1);
  return text;
}

template <class Int>
NumberError parse_integer(std::string_view text, Int& out) {
  text = without_plus(text);
  if (text.empty()) return NumberError::kNotDecimal;
  if constexpr (std::is_unsigned_v<Int>) {
    if (text[0] == '-') {  // a negative number, not a malformed one
      Int magnitude = 0;
      const NumberError e = parse_integer(text.substr(1), magnitude);
      if (e != NumberError::kNone || text.size() < 2 || !is_digit(text[1])) return NumberError::kNotDecimal;
      if (magnitude != 0) return NumberError::kOutOfRange;
      out = 0;
      return NumberError::kNone;
    }
  }
  const char* end = text.data() + text.size();
  Int value = 0;
  const auto [ptr, ec] = std::from_chars(text.data(), end, value, 10);
  if (ec == std::errc::result_out_of_range) {
    // Only a run of digits overflows: anything after it still makes the text malformed.
    const char* p = text.data() + (text[0] == '-' ? 1 : 0);
    while (p != end && is_digit(*p)) ++p;
    return p == end ? NumberError::kOutOfRange : NumberError::kNotDecimal;
  }
  if (ec != std::errc() || ptr != end) return NumberError::kNotDecimal;
  out = value;
  return NumberError::kNone;
}

}  // namespace

const char* describe(NumberError e) {
  switch (e) {
    case NumberError::kNone:
      return "";
    case NumberError::kNotDecimal:
      return "is not a decimal number";
    case NumberError::kOutOfRange:
      return "is out of range";
  }
  return "";
}

NumberError parse_decimal(std::string_view text, double& out) {
  text = without_plus(text);
  if (text.empty()) return NumberError::kNotDecimal;
  // from_chars also reads "inf", "nan" and "infinity": a number starts with a digit or a point.
  const std::size_t first = text[0] == '-' ? 1 : 0;
  if (first >= text.size() || !(is_digit(text[first]) || text[first] == '.')) return NumberError::kNotDecimal;
  const char* end = text.data() + text.size();
  double value = 0.0;
  const auto [ptr, ec] = std::from_chars(text.data(), end, value, std::chars_format::general);
  if (ptr != end) return NumberError::kNotDecimal;  // "0x1p1" stops at the 'x'
  if (ec == std::errc::result_out_of_range || (ec == std::errc() && !std::isfinite(value)))
    return NumberError::kOutOfRange;
  if (ec != std::errc()) return NumberError::kNotDecimal;
  out = value;
  return NumberError::kNone;
}

NumberError parse_decimal(std::string_view text, std::int64_t& out) { return parse_integer(text, out); }
NumberError parse_decimal(std::string_view text, std::uint64_t& out) { return parse_integer(text, out); }
NumberError parse_decimal(std::string_view text, std::int32_t& out) { return parse_integer(text, out); }
NumberError parse_decimal(std::string_view text, std::uint32_t& out) { return parse_integer(text, out); }

std::string number_problem(const std::string& what, std::string_view text, NumberError e) {
  return what + " '" + std::string(text) + "' " + describe(e);
}

std::string range_problem(const std::string& what, double value, double min, double max) {
  std::ostringstream s;
  s << what << ' ' << value << " is outside [" << min << ", " << max << "]";
  return s.str();
}

double decimal_or_throw(std::string_view text, const std::string& what) {
  double v = 0.0;
  const NumberError e = parse_decimal(text, v);
  if (e != NumberError::kNone) throw std::invalid_argument(number_problem(what, text, e));
  return v;
}

void append_decimal(std::string& out, double value) {
  char buffer[32];
  const auto [end, ec] = std::to_chars(buffer, buffer + sizeof buffer, value);  // shortest round trip
  out.append(buffer, end);
}

}  // namespace beaconloc
