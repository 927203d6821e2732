#include "beaconloc/core/occupancy_grid_io.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>
#include <vector>

#include "beaconloc/core/limits.hpp"
#include "beaconloc/core/yaml_document.hpp"

namespace beaconloc {
namespace {

[[noreturn]] void fail(const std::string& path, const std::string& what) {
  throw MapFileError(path + ": " + what);
}

// "path:line: what", the line of the node the complaint is about.
[[noreturn]] void fail_at(const std::string& path, const YAML::Node& at, const std::string& what) {
  const YAML::Mark mark = at.Mark();
  fail(mark.line >= 0 ? path + ":" + std::to_string(mark.line + 1) : path, what);
}

// The keys of a map_server YAML file (ROS 2 nav2 map_server, map_io).
const std::set<std::string> kMapKeys = {"image",           "resolution",  "origin", "negate",
                                        "occupied_thresh", "free_thresh", "mode"};

// The next PGM header token, skipping whitespace and '#' comments.
std::string header_token(std::istream& in, const std::string& path) {
  std::string token;
  while (in) {
    const int c = in.get();
    if (c == '#') {
      std::string comment;
      std::getline(in, comment);
    } else if (std::isspace(c)) {
      if (!token.empty()) return token;
    } else if (c != EOF) {
      token.push_back(static_cast<char>(c));
    }
  }
  if (token.empty()) fail(path, "truncated PGM header");
  return token;
}

int header_number(std::istream& in, const std::string& path, const char* what, int max) {
  const std::string token = header_token(in, path);
  int value = 0;
  const NumberError e = parse_decimal(token, value);
  if (e != NumberError::kNone) fail(path, number_problem(std::string("PGM ") + what, token, e));
  if (value < 1 || value > max) fail(path, range_problem(std::string("PGM ") + what, value, 1, max));
  return value;
}

// A number of the YAML file: a decimal scalar (core/decimal.hpp) within [min, max].
double number(const YAML::Node& node, const std::string& key, const std::string& path, double min,
              double max) {
  if (!node.IsScalar()) fail_at(path, node, "'" + key + "' must be a number");
  double v = 0.0;
  const NumberError e = yaml_number(node, v);
  if (e != NumberError::kNone) fail_at(path, node, number_problem(key, node.Scalar(), e));
  if (!(v >= min && v <= max)) fail_at(path, node, range_problem(key, v, min, max));
  return v;
}

// What the YAML file says, checked.
struct MapYaml {
  std::string image;
  double resolution = 0.0;
  double origin_x = 0.0;
  double origin_y = 0.0;
  double occupied_thresh = 0.65;
  double free_thresh = 0.196;
  bool negate = false;
};

MapYaml read_map_yaml(const YAML::Node& root, const std::string& path) {
  MapYaml map;
  if (!root.IsMap()) fail(path, "not a map file: a mapping of image, resolution, origin, ...");
  for (const auto& kv : root) {
    const std::string key = kv.first.IsScalar() ? kv.first.Scalar() : std::string();
    if (!kMapKeys.count(key)) {
      fail_at(path, kv.first,
              "'" + key +
                  "' is not a map file key (image, resolution, origin, negate, occupied_thresh, "
                  "free_thresh, mode)");
    }
  }
  if (!root["image"]) fail(path, "missing 'image'");
  if (!root["image"].IsScalar() || root["image"].Scalar().empty())
    fail_at(path, root["image"], "'image' must be a file name");
  map.image = root["image"].Scalar();
  if (!root["resolution"]) fail(path, "missing 'resolution'");
  map.resolution = number(root["resolution"], "resolution", path, OccupancyGrid::kMinResolutionM,
                          OccupancyGrid::kMaxResolutionM);
  const YAML::Node origin = root["origin"];
  if (!origin) fail(path, "missing 'origin'");
  if (!origin.IsSequence() || origin.size() != 3) fail_at(path, origin, "'origin' must be [x, y, yaw]");
  map.origin_x = number(origin[0], "origin[0]", path, -kMaxMapCoordinateM, kMaxMapCoordinateM);
  map.origin_y = number(origin[1], "origin[1]", path, -kMaxMapCoordinateM, kMaxMapCoordinateM);
  if (number(origin[2], "origin[2]", path, -kMaxMapCoordinateM, kMaxMapCoordinateM) != 0.0)
    fail_at(path, origin[2], "'origin' yaw must be 0 (rotated maps are not supported)");
  if (root["occupied_thresh"])
    map.occupied_thresh = number(root["occupied_thresh"], "occupied_thresh", path, 0.0, 1.0);
  if (root["free_thresh"]) map.free_thresh = number(root["free_thresh"], "free_thresh", path, 0.0, 1.0);
  if (map.free_thresh > map.occupied_thresh)
    fail(path, "free_thresh must not exceed occupied_thresh (" + std::to_string(map.free_thresh) + " > " +
                   std::to_string(map.occupied_thresh) + ")");
  if (const YAML::Node negate = root["negate"]) {
    // map_server writes 0 or 1; a YAML boolean says the same.
    const std::string v = negate.IsScalar() ? negate.Scalar() : std::string();
    bool as_bool = false;
    if (v == "0" || v == "1") {
      map.negate = v == "1";
    } else if (YAML::convert<bool>::decode(negate, as_bool)) {
      map.negate = as_bool;
    } else {
      fail_at(path, negate, "'negate' must be 0 or 1, not '" + v + "'");
    }
  }
  if (const YAML::Node mode = root["mode"]) {
    if (!mode.IsScalar() || mode.Scalar() != "trinary")
      fail_at(path, mode, "only 'mode: trinary' (the default) is supported");
  }
  return map;
}

// The PGM image (P5 or P2) as the grid the YAML describes; image_path names it in messages.
OccupancyGrid read_pgm(std::istream& in, const MapYaml& map, const std::string& image_path) {
  const std::string magic = header_token(in, image_path);
  if (magic != "P5" && magic != "P2") fail(image_path, "not a PGM image (P5 or P2)");
  const int width = header_number(in, image_path, "width", OccupancyGrid::kMaxCellsPerSide);
  const int height = header_number(in, image_path, "height", OccupancyGrid::kMaxCellsPerSide);
  const std::size_t cells = static_cast<std::size_t>(width) * static_cast<std::size_t>(height);
  if (static_cast<std::int64_t>(cells) > OccupancyGrid::kMaxCells) {
    std::ostringstream why;
    why << "PGM of " << width << " x " << height << " pixels: more than " << OccupancyGrid::kMaxCells;
    fail(image_path, why.str());
  }
  const int max_value = header_number(in, image_path, "maximum value", 65535);
  if (max_value > 255) fail(image_path, "16-bit PGM is not supported");
  std::vector<int> pixels;
  if (magic == "P5") {  // the data must be there before anything is allocated for it, and no more
    const auto here = in.tellg();
    in.seekg(0, std::ios::end);
    const auto size = in.tellg();
    in.seekg(here);
    const auto data = static_cast<std::size_t>(size - here);
    if (data < cells) fail(image_path, "truncated PGM data");
    if (data > cells) {
      fail(image_path, std::to_string(data - cells) + " bytes after the image's " + std::to_string(cells) +
                           " pixels (one image per file)");
    }
    pixels.resize(cells);
    std::vector<unsigned char> raw(pixels.size());
    in.read(reinterpret_cast<char*>(raw.data()), static_cast<std::streamsize>(raw.size()));
    if (in.gcount() != static_cast<std::streamsize>(raw.size())) fail(image_path, "truncated PGM data");
    for (std::size_t i = 0; i < raw.size(); ++i) {
      if (raw[i] > max_value) fail(image_path, "a pixel above the PGM's maximum value");
      pixels[i] = raw[i];
    }
  } else {  // pixel by pixel: a header's size alone allocates nothing (4e8 bytes for 20 bytes of text)
    pixels.reserve(std::min<std::size_t>(cells, 1 << 16));
    std::string token;
    for (std::size_t i = 0; i < cells; ++i) {
      int p = 0;
      if (!(in >> token) || parse_decimal(token, p) != NumberError::kNone || p < 0 || p > max_value)
        fail(image_path, "bad or truncated PGM data");
      pixels.push_back(p);
    }
    if (in >> token) fail(image_path, "data after the image's " + std::to_string(cells) + " pixels");
  }
  OccupancyGrid grid({map.origin_x, map.origin_y}, map.resolution, width, height);
  for (int row = 0; row < height; ++row) {
    for (int col = 0; col < width; ++col) {
      const double p = static_cast<double>(pixels[static_cast<std::size_t>(row) * width + col]) / max_value;
      const double occupancy = map.negate ? p : 1.0 - p;
      grid.set_occupied(col, height - 1 - row, occupancy > map.occupied_thresh);  // top row: largest y
    }
  }
  return grid;
}

YAML::Node load_map_yaml(const std::string& text, const std::string& origin) {
  try {
    return load_yaml(text, origin);
  } catch (const YamlError& e) {
    throw MapFileError(e.what());
  }
}

}  // namespace

OccupancyGrid load_occupancy_grid(const std::string& yaml_path) {
  std::ifstream file(yaml_path);
  if (!file) fail(yaml_path, "cannot read the map file");
  std::stringstream text;
  text << file.rdbuf();
  const YAML::Node root = load_map_yaml(text.str(), yaml_path);
  const MapYaml map = read_map_yaml(root, yaml_path);
  std::filesystem::path image = map.image;
  if (image.is_relative()) image = std::filesystem::path(yaml_path).parent_path() / image;
  std::ifstream in(image, std::ios::binary);
  if (!in) fail(image.string(), "cannot open the map image");
  return read_pgm(in, map, image.string());
}

OccupancyGrid parse_occupancy_grid(const std::string& yaml_text, const std::string& image_bytes,
                                   const std::string& yaml_origin, const std::string& image_origin) {
  const YAML::Node root = load_map_yaml(yaml_text, yaml_origin);
  const MapYaml map = read_map_yaml(root, yaml_origin);
  std::istringstream in(image_bytes, std::ios::in | std::ios::binary);
  return read_pgm(in, map, image_origin);
}

void write_occupancy_grid(const OccupancyGrid& grid, const std::string& yaml_path) {
  const std::filesystem::path yaml(yaml_path);
  const std::filesystem::path pgm = std::filesystem::path(yaml).replace_extension(".pgm");
  std::ofstream image(pgm, std::ios::binary);
  image << "P5\n# beaconloc occupancy grid\n" << grid.width() << ' ' << grid.height() << "\n255\n";
  for (int row = 0; row < grid.height(); ++row) {
    for (int col = 0; col < grid.width(); ++col) {
      image.put(static_cast<char>(grid.occupied(col, grid.height() - 1 - row) ? 0 : 254));
    }
  }
  if (!image) fail(pgm.string(), "cannot write the map image");
  std::ofstream out(yaml);
  out.precision(17);
  out << "image: " << pgm.filename().string() << "\nresolution: " << grid.resolution_m() << "\norigin: ["
      << grid.origin_m().x() << ", " << grid.origin_m().y() << ", 0.0]\nnegate: 0\noccupied_thresh: 0.65\n"
      << "free_thresh: 0.196\n";
  if (!out) fail(yaml_path, "cannot write the map file");
}

}  // namespace beaconloc
