// The one parser of the numbers in files and options (core/decimal.hpp), and the readers that
// use it: --param values, --fault specs and the numeric command-line options (number_options).
#include "beaconloc/core/decimal.hpp"

#include <gtest/gtest.h>

#include <limits>

#include "beaconloc/core/estimator.hpp"
#include "number_options.hpp"
#include "sim/faults.hpp"

namespace beaconloc {
namespace {

NumberError real(const std::string& text, double* out = nullptr) {
  double v = -42.0;
  const NumberError e = parse_decimal(text, v);
  if (out) *out = v;
  return e;
}

TEST(Decimal, NumbersAreDecimalAndNothingElse) {
  for (const auto& [text, value] : std::initializer_list<std::pair<const char*, double>>{{"12", 12.0},
                                                                                         {"-0.5", -0.5},
                                                                                         {".25", 0.25},
                                                                                         {"+2", 2.0},
                                                                                         {"1e-3", 1e-3},
                                                                                         {"2.5E2", 250.0},
                                                                                         {"-0", 0.0},
                                                                                         {"1.", 1.0},
                                                                                         {"1e308", 1e308}}) {
    double v = 0.0;
    EXPECT_EQ(real(text, &v), NumberError::kNone) << text;
    EXPECT_EQ(v, value) << text;
  }
  // Hexadecimal (std::strtod read "0x1p1" as 2), words, whitespace, junk before or after.
  for (const char* text :
       {"0x1p1", "0x10", "inf", "-inf", "nan", "infinity", " 1", "1 ", "\t1", "1\n",  "1,5",  "1.5m",
        "",      "-",    "+",   "+-1",  "--1", ".",        "e5", "1e", "1e+", "1..2", "1e5.5"}) {
    EXPECT_EQ(real(text), NumberError::kNotDecimal) << "'" << text << "'";
  }
  // Beyond a double: an error, not infinity or zero; the value is left alone.
  double v = 7.0;
  EXPECT_EQ(parse_decimal("1e400", v), NumberError::kOutOfRange);
  EXPECT_EQ(parse_decimal("-1e400", v), NumberError::kOutOfRange);
  EXPECT_EQ(parse_decimal("1e-400", v), NumberError::kOutOfRange);
  EXPECT_EQ(v, 7.0);
  EXPECT_EQ(number_problem("range_m", "1e400", NumberError::kOutOfRange), "range_m '1e400' is out of range");
  EXPECT_EQ(number_problem("x", "0x1p1", NumberError::kNotDecimal), "x '0x1p1' is not a decimal number");
  EXPECT_EQ(range_problem("v_mps", 1e300, -10, 10), "v_mps 1e+300 is outside [-10, 10]");
}

TEST(Decimal, WholeNumbersAreDecimalDigitsWithinTheirType) {
  std::int64_t i = 0;
  EXPECT_EQ(parse_decimal("010", i), NumberError::kNone);  // not octal
  EXPECT_EQ(i, 10);
  EXPECT_EQ(parse_decimal("-9223372036854775808", i), NumberError::kNone);
  EXPECT_EQ(i, std::numeric_limits<std::int64_t>::min());
  EXPECT_EQ(parse_decimal("9223372036854775808", i), NumberError::kOutOfRange);
  for (const char* text : {"1.0", "1e3", "0x10", " 1", "1x", "", "-", "+-1"}) {
    EXPECT_EQ(parse_decimal(text, i), NumberError::kNotDecimal) << text;
  }
  std::uint64_t u = 5;
  EXPECT_EQ(parse_decimal("-1", u), NumberError::kOutOfRange);  // never 2^64 - 1
  EXPECT_EQ(parse_decimal("-0", u), NumberError::kNone);
  EXPECT_EQ(u, 0u);
  EXPECT_EQ(parse_decimal("18446744073709551615", u), NumberError::kNone);
  EXPECT_EQ(parse_decimal("18446744073709551616", u), NumberError::kOutOfRange);
  EXPECT_EQ(parse_decimal("-x", u), NumberError::kNotDecimal);
  std::uint32_t id = 0;
  EXPECT_EQ(parse_decimal("4294967296", id), NumberError::kOutOfRange);
  std::int32_t n = 0;
  EXPECT_EQ(parse_decimal("+16", n), NumberError::kNone);
  EXPECT_EQ(n, 16);
}

std::string param_error(const std::string& item) {
  try {
    parse_estimator_parameters({item}, "--param");
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "";
}

TEST(Decimal, ParamValuesAndFaultsUseTheOneParser) {
  EXPECT_EQ(param_error("nis_gate=0x1p1"),
            "--param 'nis_gate=0x1p1': the value '0x1p1' is not a decimal number");
  EXPECT_EQ(param_error("nis_gate=1e400"), "--param 'nis_gate=1e400': the value '1e400' is out of range");
  EXPECT_EQ(param_error("nis_gate= 3"), "--param 'nis_gate= 3': the value ' 3' is not a decimal number");
  EXPECT_EQ(param_error("nis_gate=9.2"), "");
  sim::Scenario s = sim::default_scenario();
  const auto fault_error = [&](const std::string& spec) {
    try {
      sim::apply_fault(s, spec);
    } catch (const std::invalid_argument& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  EXPECT_NE(fault_error("beacon_dies=1@0x10").find("the time '0x10' is not a decimal number"),
            std::string::npos);
  EXPECT_NE(fault_error("beacon_dies=1@1e300").find("the time 1e+300 is outside [0, 1e+06]"),
            std::string::npos);
  EXPECT_NE(fault_error("tof_outage=0:1e300").find("TO 1e+300 is outside"), std::string::npos);
  EXPECT_NE(fault_error("beacon_dies=-1@3").find("the beacon id '-1' is out of range"), std::string::npos);
}

// The numeric options as the command line parses them: CLI11 names the option, the validator
// says what is wrong with the text as typed.
std::string option_error(const std::vector<std::string>& argv) {
  CLI::App app;
  double max_age_ms = 600.0, pose = 0.0;
  std::optional<std::uint64_t> seed;
  int count = 3;
  app.add_option("--max-age-ms", max_age_ms)->transform(cli::real_in(0.0, 6e4, true));
  app.add_option("--seed", seed)->transform(cli::any_unsigned());
  app.add_option("--receiver-count", count)->transform(cli::whole_in(1, 16));
  app.add_option("--x", pose)->transform(cli::real_in(-1e6, 1e6));
  std::vector<std::string> reversed(argv.rbegin(), argv.rend());
  try {
    app.parse(reversed);
  } catch (const CLI::ParseError& e) {
    return e.what();
  }
  if (app.count("--receiver-count")) {
    EXPECT_EQ(count, 10);  // "010" is ten, not octal
  }
  if (seed) {
    EXPECT_EQ(*seed, 7u);
  }
  return "";
}

TEST(NumberOptions, EveryNumericOptionIsADecimalWithinItsRangeNamedAsTyped) {
  EXPECT_EQ(option_error({"--max-age-ms", "1e300"}), "--max-age-ms: '1e300' is outside (0, 60000]");
  EXPECT_EQ(option_error({"--max-age-ms", "0"}), "--max-age-ms: '0' is outside (0, 60000]");
  EXPECT_EQ(option_error({"--max-age-ms", "0x1p1"}), "--max-age-ms: '0x1p1' is not a decimal number");
  EXPECT_EQ(option_error({"--max-age-ms", "1e400"}), "--max-age-ms: '1e400' is out of range");
  EXPECT_EQ(option_error({"--seed", "-1"}), "--seed: '-1' is outside [0, 18446744073709551615]");
  EXPECT_EQ(option_error({"--seed", "0x7"}), "--seed: '0x7' is not a whole decimal number");
  EXPECT_EQ(option_error({"--receiver-count", "17"}), "--receiver-count: '17' is outside [1, 16]");
  EXPECT_EQ(option_error({"--receiver-count", "2.5"}),
            "--receiver-count: '2.5' is not a whole decimal number");
  EXPECT_EQ(option_error({"--x", "nan"}), "--x: 'nan' is not a decimal number");
  EXPECT_EQ(option_error({"--seed", "7", "--receiver-count", "010", "--max-age-ms", "600"}), "");
}

}  // namespace
}  // namespace beaconloc
