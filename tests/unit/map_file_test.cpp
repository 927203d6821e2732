// The map file loader (core/occupancy_grid_io.hpp): every number of the YAML and the PGM is
// range-checked with a reason naming its key, unknown keys and bytes after the image are refused.
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>

#include "beaconloc/core/occupancy_grid_io.hpp"

namespace beaconloc {
namespace {

const std::string kPgm = "P2\n3 2\n255\n0 254 254\n254 254 0\n";

std::string error_of(const std::string& yaml, const std::string& image = kPgm) {
  try {
    parse_occupancy_grid(yaml, image, "m.yaml", "m.pgm");
  } catch (const MapFileError& e) {
    return e.what();
  }
  return "";
}

std::string yaml_with(const std::string& resolution, const std::string& origin,
                      const std::string& extra = "") {
  return "image: m.pgm\nresolution: " + resolution + "\norigin: " + origin + "\n" + extra;
}

TEST(MapFile, EveryNumberIsRangeCheckedWithAReasonNamingItsKey) {
  const std::string origin = "[0, 0, 0]";
  // The numbers that made ray casting spin (issue 23, item 3).
  EXPECT_EQ(error_of(yaml_with("1e-300", origin)), "m.yaml:2: resolution 1e-300 is outside [0.001, 10]");
  EXPECT_EQ(error_of(yaml_with("0.05", "[1e300, 0, 0]")),
            "m.yaml:3: origin[0] 1e+300 is outside [-1e+06, 1e+06]");
  EXPECT_EQ(error_of(yaml_with("0.05", "[0, -2e6, 0]")),
            "m.yaml:3: origin[1] -2e+06 is outside [-1e+06, 1e+06]");
  EXPECT_EQ(error_of(yaml_with("0", origin)), "m.yaml:2: resolution 0 is outside [0.001, 10]");
  EXPECT_EQ(error_of(yaml_with("0x1p1", origin)), "m.yaml:2: resolution '0x1p1' is not a decimal number");
  EXPECT_EQ(error_of(yaml_with(".nan", origin)), "m.yaml:2: resolution '.nan' is not a decimal number");
  EXPECT_EQ(error_of(yaml_with("1e400", origin)), "m.yaml:2: resolution '1e400' is out of range");
  EXPECT_EQ(error_of(yaml_with("[1]", origin)), "m.yaml:2: 'resolution' must be a number");
  EXPECT_EQ(error_of(yaml_with("0.05", "[0, 0]")), "m.yaml:3: 'origin' must be [x, y, yaw]");
  EXPECT_EQ(error_of(yaml_with("0.05", "[0, 0, 0.5]")),
            "m.yaml:3: 'origin' yaw must be 0 (rotated maps are not supported)");
  EXPECT_EQ(error_of(yaml_with("0.05", origin, "occupied_thresh: 7\n")),
            "m.yaml:4: occupied_thresh 7 is outside [0, 1]");
  EXPECT_EQ(error_of(yaml_with("0.05", origin, "free_thresh: -0.1\n")),
            "m.yaml:4: free_thresh -0.1 is outside [0, 1]");
  EXPECT_EQ(error_of(yaml_with("0.05", origin, "occupied_thresh: 0.3\nfree_thresh: 0.5\n")),
            "m.yaml: free_thresh must not exceed occupied_thresh (0.500000 > 0.300000)");
  EXPECT_EQ(error_of(yaml_with("0.05", origin, "negate: 2\n")), "m.yaml:4: 'negate' must be 0 or 1, not '2'");
  EXPECT_EQ(error_of(yaml_with("0.05", origin, "mode: scale\n")),
            "m.yaml:4: only 'mode: trinary' (the default) is supported");
  // Unknown keys and keys given twice (core/yaml_document.hpp).
  EXPECT_EQ(error_of(yaml_with("0.05", origin, "colour: red\n")),
            "m.yaml:4: 'colour' is not a map file key (image, resolution, origin, negate, occupied_thresh, "
            "free_thresh, mode)");
  EXPECT_EQ(error_of(yaml_with("0.05", origin, "resolution: 0.1\n")),
            "m.yaml:4: 'resolution' is repeated (first at line 2)");
  // A good file with every key loads.
  EXPECT_EQ(error_of(yaml_with("0.05", "[-1.5, 2.0, 0.0]",
                               "negate: 0\noccupied_thresh: 0.65\nfree_thresh: 0.196\nmode: trinary\n")),
            "");
}

TEST(MapFile, ThePgmsNumbersAreCheckedAndNothingMayFollowTheImage) {
  const std::string yaml = yaml_with("0.05", "[0, 0, 0]");
  const std::string p5 = std::string("P5\n2 1\n255\n") + '\0' + '\xfe';
  EXPECT_EQ(error_of(yaml, p5), "");
  EXPECT_EQ(error_of(yaml, p5 + "\n"), "m.pgm: 1 bytes after the image's 2 pixels (one image per file)");
  EXPECT_EQ(error_of(yaml, p5 + p5), "m.pgm: 13 bytes after the image's 2 pixels (one image per file)");
  EXPECT_EQ(error_of(yaml, kPgm + "7\n"), "m.pgm: data after the image's 6 pixels");
  EXPECT_EQ(error_of(yaml, kPgm + "\n \n"), "");  // whitespace after a text image is no data
  EXPECT_EQ(error_of(yaml, "P2\n30000 1\n255\n0\n"), "m.pgm: PGM width 30000 is outside [1, 20000]");
  EXPECT_EQ(error_of(yaml, "P2\n20000 20000\n255\n0\n"),
            "m.pgm: PGM of 20000 x 20000 pixels: more than 100000000");
  EXPECT_EQ(error_of(yaml, "P2\n0x3 2\n255\n0\n"), "m.pgm: PGM width '0x3' is not a decimal number");
  EXPECT_EQ(error_of(yaml, "P2\n3 2\n0\n0\n"), "m.pgm: PGM maximum value 0 is outside [1, 65535]");
  EXPECT_EQ(error_of(yaml, "P2\n3 2\n255\n0 254 254\n254 254 0x0\n"), "m.pgm: bad or truncated PGM data");
  EXPECT_EQ(error_of(yaml, "P2\n3 2\n255\n0 254 254\n254 254 +0\n"), "");  // a decimal with a sign
}

}  // namespace
}  // namespace beaconloc
