// The one loader of the project's YAML files (core/yaml_document.hpp): a key given twice at any
// depth, a key that is an alias, a second document are errors naming the key and its line.
#include "beaconloc/core/yaml_document.hpp"

#include <gtest/gtest.h>

namespace beaconloc {
namespace {

std::string error_of(const std::string& text) {
  try {
    load_yaml(text, "f.yaml");
  } catch (const YamlError& e) {
    return e.what();
  }
  return "";
}

TEST(YamlDocument, YamlCppAloneKeepsBothPairsOfADuplicateKeyAndReturnsTheFirst) {
  // Why the check exists: yaml-cpp accepts the file, iteration shows both pairs, lookup the first.
  const YAML::Node n = YAML::Load("range_sigma_m: 0.01\nrange_sigma_m: 0.5\n");
  int pairs = 0;
  for (const auto& kv : n) pairs += kv.first.Scalar() == "range_sigma_m";
  EXPECT_EQ(pairs, 2);
  EXPECT_EQ(n["range_sigma_m"].Scalar(), "0.01");
}

TEST(YamlDocument, ADuplicateKeyAtAnyDepthIsAnErrorNamingTheKeyAndBothLines) {
  EXPECT_EQ(error_of("a: 1\nb: 2\na: 3\n"), "f.yaml:3: 'a' is repeated (first at line 1)");
  EXPECT_EQ(error_of("beacon_system:\n  range_sigma_m: 0.01\n  max_range_m: 5\n  range_sigma_m: 0.5\n"),
            "f.yaml:4: 'beacon_system.range_sigma_m' is repeated (first at line 2)");
  EXPECT_EQ(error_of("beacons:\n  - {id: 1, position_m: [0, 0, 2]}\n  - {id: 2, id: 3}\n"),
            "f.yaml:3: 'beacons[1].id' is repeated (first at line 3)");
  EXPECT_EQ(error_of("a:\n  b:\n    - c: 1\n      d: {e: 1, \"e\": 2}\n"),
            "f.yaml:4: 'a.b[0].d.e' is repeated (first at line 4)");  // quoting names the same key
  // The same key in two different mappings is no repetition; nor are equal values.
  EXPECT_EQ(error_of("a: {x: 1}\nb: {x: 1}\nc: [{x: 1}, {x: 1}]\n"), "");
}

TEST(YamlDocument, AnAliasKeyAndASecondDocumentAreErrorsAliasValuesAreFine) {
  EXPECT_EQ(error_of("k: &name x\nmap:\n  *name : 1\n"), "f.yaml:3: 'map' has a key that is an alias");
  EXPECT_EQ(error_of("a: 1\n---\na: 2\n"), "f.yaml:2: a second YAML document (a file holds one)");
  EXPECT_EQ(error_of("base: &b [1, 2]\nother: *b\n"), "");
  const YAML::Node n = load_yaml("base: &b [1, 2]\nother: *b\n", "f.yaml");
  EXPECT_EQ(n["other"].size(), 2u);
  EXPECT_EQ(error_of("a: [1, 2\n").rfind("f.yaml:2: not valid YAML: ", 0), 0u) << error_of("a: [1, 2\n");
  EXPECT_EQ(error_of(""), "");
}

TEST(YamlDocument, NumbersAreReadByTheOneDecimalParser) {
  const YAML::Node n = load_yaml("a: 010\nb: 0x10\nc: .inf\nd: 1.5\ne: [1]\n", "f.yaml");
  std::int64_t i = 0;
  EXPECT_EQ(yaml_number(n["a"], i), NumberError::kNone);
  EXPECT_EQ(i, 10);                                             // yaml-cpp alone reads 8
  EXPECT_EQ(yaml_number(n["b"], i), NumberError::kNotDecimal);  // yaml-cpp alone reads 16
  double d = 0.0;
  EXPECT_EQ(yaml_number(n["c"], d), NumberError::kNotDecimal);  // yaml-cpp alone reads infinity
  EXPECT_EQ(yaml_number(n["d"], d), NumberError::kNone);
  EXPECT_EQ(d, 1.5);
  EXPECT_EQ(yaml_number(n["e"], d), NumberError::kNotDecimal);
}

}  // namespace
}  // namespace beaconloc
