#include "beaconloc/core/occupancy_grid_io.hpp"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <vector>

namespace beaconloc {
namespace {

[[noreturn]] void fail(const std::string& path, const std::string& what) {
  throw MapFileError(path + ": " + what);
}

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

int header_number(std::istream& in, const std::string& path, const char* what) {
  const std::string token = header_token(in, path);
  std::size_t used = 0;
  int value = 0;
  try {
    value = std::stoi(token, &used);
  } catch (const std::exception&) {
    used = 0;
  }
  if (used != token.size() || value <= 0) fail(path, std::string("bad PGM ") + what + " '" + token + "'");
  return value;
}

double number(const YAML::Node& root, const char* key, const std::string& path) {
  if (!root[key]) fail(path, std::string("missing '") + key + "'");
  try {
    const double v = root[key].as<double>();
    if (!std::isfinite(v)) fail(path, std::string("'") + key + "' is not finite");
    return v;
  } catch (const YAML::Exception&) {
    fail(path, std::string("'") + key + "' is not a number");
  }
}

// What the YAML file says, checked.
struct MapYaml {
  std::string image;
  double resolution = 0.0;
  double origin_x = 0.0;
  double origin_y = 0.0;
  double occupied_thresh = 0.65;
  bool negate = false;
};

MapYaml read_map_yaml(const YAML::Node& root, const std::string& yaml_path) {
  MapYaml map;
  if (!root.IsMap() || !root["image"]) fail(yaml_path, "missing 'image'");
  map.resolution = number(root, "resolution", yaml_path);
  if (!(map.resolution > 0.0)) fail(yaml_path, "'resolution' must be positive");
  const YAML::Node origin = root["origin"];
  if (!origin || !origin.IsSequence() || origin.size() != 3) fail(yaml_path, "'origin' must be [x, y, yaw]");
  double oyaw = 0.0;
  try {
    map.origin_x = origin[0].as<double>();
    map.origin_y = origin[1].as<double>();
    oyaw = origin[2].as<double>();
  } catch (const YAML::Exception&) {
    fail(yaml_path, "'origin' must hold three numbers");
  }
  if (!std::isfinite(map.origin_x) || !std::isfinite(map.origin_y) || oyaw != 0.0) {
    fail(yaml_path, "'origin' must be finite with yaw 0 (rotated maps are not supported)");
  }
  map.occupied_thresh = root["occupied_thresh"] ? number(root, "occupied_thresh", yaml_path) : 0.65;
  if (!(map.occupied_thresh >= 0.0 && map.occupied_thresh <= 1.0))
    fail(yaml_path, "'occupied_thresh' must be in [0, 1]");
  if (root["free_thresh"]) {
    const double free_thresh = number(root, "free_thresh", yaml_path);
    if (!(free_thresh >= 0.0 && free_thresh <= 1.0)) fail(yaml_path, "'free_thresh' must be in [0, 1]");
  }
  if (root["negate"]) {
    try {
      map.negate = root["negate"].as<int>() != 0;
    } catch (const YAML::Exception&) {
      try {
        map.negate = root["negate"].as<bool>();
      } catch (const YAML::Exception&) {
        fail(yaml_path, "'negate' must be 0 or 1");
      }
    }
  }
  if (root["mode"] && root["mode"].as<std::string>("") != "trinary") {
    fail(yaml_path, "only 'mode: trinary' (the default) is supported");
  }
  try {
    map.image = root["image"].as<std::string>();
  } catch (const YAML::Exception&) {
    fail(yaml_path, "'image' must be a file name");
  }
  return map;
}

// The PGM image (P5 or P2) as the grid the YAML describes; image_path names it in messages.
OccupancyGrid read_pgm(std::istream& in, const MapYaml& map, const std::string& image_path) {
  const std::string magic = header_token(in, image_path);
  if (magic != "P5" && magic != "P2") fail(image_path, "not a PGM image (P5 or P2)");
  const int width = header_number(in, image_path, "width");
  const int height = header_number(in, image_path, "height");
  const int max_value = header_number(in, image_path, "maximum value");
  if (max_value > 255) fail(image_path, "16-bit PGM is not supported");
  const std::size_t cells = static_cast<std::size_t>(width) * static_cast<std::size_t>(height);
  if (magic == "P5") {  // the data must be there before anything is allocated for it
    const auto here = in.tellg();
    in.seekg(0, std::ios::end);
    const auto size = in.tellg();
    in.seekg(here);
    if (size - here < static_cast<std::streamoff>(cells)) fail(image_path, "truncated PGM data");
  } else if (cells > 100'000'000) {
    fail(image_path, "more than 1e8 cells in a text PGM");
  }
  std::vector<int> pixels;
  if (magic == "P5") {
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
    for (std::size_t i = 0; i < cells; ++i) {
      int p = 0;
      if (!(in >> p) || p < 0 || p > max_value) fail(image_path, "bad or truncated PGM data");
      pixels.push_back(p);
    }
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

}  // namespace

OccupancyGrid load_occupancy_grid(const std::string& yaml_path) {
  YAML::Node root;
  try {
    root = YAML::LoadFile(yaml_path);
  } catch (const YAML::Exception& e) {
    fail(yaml_path, std::string("not a readable YAML map: ") + e.what());
  }
  const MapYaml map = read_map_yaml(root, yaml_path);
  std::filesystem::path image = map.image;
  if (image.is_relative()) image = std::filesystem::path(yaml_path).parent_path() / image;
  std::ifstream in(image, std::ios::binary);
  if (!in) fail(image.string(), "cannot open the map image");
  return read_pgm(in, map, image.string());
}

OccupancyGrid parse_occupancy_grid(const std::string& yaml_text, const std::string& image_bytes,
                                   const std::string& yaml_origin, const std::string& image_origin) {
  YAML::Node root;
  try {
    root = YAML::Load(yaml_text);
  } catch (const YAML::Exception& e) {
    fail(yaml_origin, std::string("not a readable YAML map: ") + e.what());
  }
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
