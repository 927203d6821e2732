#include "beaconloc/core/occupancy_grid_io.hpp"

#include <yaml-cpp/yaml.h>

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

}  // namespace

OccupancyGrid load_occupancy_grid(const std::string& yaml_path) {
  YAML::Node root;
  try {
    root = YAML::LoadFile(yaml_path);
  } catch (const YAML::Exception& e) {
    fail(yaml_path, std::string("not a readable YAML map: ") + e.what());
  }
  if (!root.IsMap() || !root["image"]) fail(yaml_path, "missing 'image'");
  const double resolution = number(root, "resolution", yaml_path);
  if (!(resolution > 0.0)) fail(yaml_path, "'resolution' must be positive");
  const YAML::Node origin = root["origin"];
  if (!origin || !origin.IsSequence() || origin.size() != 3) fail(yaml_path, "'origin' must be [x, y, yaw]");
  double ox = 0.0, oy = 0.0, oyaw = 0.0;
  try {
    ox = origin[0].as<double>();
    oy = origin[1].as<double>();
    oyaw = origin[2].as<double>();
  } catch (const YAML::Exception&) {
    fail(yaml_path, "'origin' must hold three numbers");
  }
  if (!std::isfinite(ox) || !std::isfinite(oy) || oyaw != 0.0) {
    fail(yaml_path, "'origin' must be finite with yaw 0 (rotated maps are not supported)");
  }
  const double occupied_thresh = root["occupied_thresh"] ? number(root, "occupied_thresh", yaml_path) : 0.65;
  if (!(occupied_thresh >= 0.0 && occupied_thresh <= 1.0))
    fail(yaml_path, "'occupied_thresh' must be in [0, 1]");
  if (root["free_thresh"]) {
    const double free_thresh = number(root, "free_thresh", yaml_path);
    if (!(free_thresh >= 0.0 && free_thresh <= 1.0)) fail(yaml_path, "'free_thresh' must be in [0, 1]");
  }
  bool negate = false;
  if (root["negate"]) {
    try {
      negate = root["negate"].as<int>() != 0;
    } catch (const YAML::Exception&) {
      try {
        negate = root["negate"].as<bool>();
      } catch (const YAML::Exception&) {
        fail(yaml_path, "'negate' must be 0 or 1");
      }
    }
  }
  if (root["mode"] && root["mode"].as<std::string>("") != "trinary") {
    fail(yaml_path, "only 'mode: trinary' (the default) is supported");
  }
  std::string image_name;
  try {
    image_name = root["image"].as<std::string>();
  } catch (const YAML::Exception&) {
    fail(yaml_path, "'image' must be a file name");
  }

  std::filesystem::path image = image_name;
  if (image.is_relative()) image = std::filesystem::path(yaml_path).parent_path() / image;
  std::ifstream in(image, std::ios::binary);
  if (!in) fail(image.string(), "cannot open the map image");
  const std::string magic = header_token(in, image.string());
  if (magic != "P5" && magic != "P2") fail(image.string(), "not a PGM image (P5 or P2)");
  const int width = header_number(in, image.string(), "width");
  const int height = header_number(in, image.string(), "height");
  const int max_value = header_number(in, image.string(), "maximum value");
  if (max_value > 255) fail(image.string(), "16-bit PGM is not supported");
  const std::size_t cells = static_cast<std::size_t>(width) * static_cast<std::size_t>(height);
  if (magic == "P5") {  // the data must be there before anything is allocated for it
    const auto here = in.tellg();
    in.seekg(0, std::ios::end);
    const auto size = in.tellg();
    in.seekg(here);
    if (size - here < static_cast<std::streamoff>(cells)) fail(image.string(), "truncated PGM data");
  } else if (cells > 100'000'000) {
    fail(image.string(), "more than 1e8 cells in a text PGM");
  }
  std::vector<int> pixels(cells);
  if (magic == "P5") {
    std::vector<unsigned char> raw(pixels.size());
    in.read(reinterpret_cast<char*>(raw.data()), static_cast<std::streamsize>(raw.size()));
    if (in.gcount() != static_cast<std::streamsize>(raw.size())) fail(image.string(), "truncated PGM data");
    for (std::size_t i = 0; i < raw.size(); ++i) {
      if (raw[i] > max_value) fail(image.string(), "a pixel above the PGM's maximum value");
      pixels[i] = raw[i];
    }
  } else {
    for (auto& p : pixels) {
      if (!(in >> p) || p < 0 || p > max_value) fail(image.string(), "bad or truncated PGM data");
    }
  }
  OccupancyGrid grid({ox, oy}, resolution, width, height);
  for (int row = 0; row < height; ++row) {
    for (int col = 0; col < width; ++col) {
      const double p = static_cast<double>(pixels[static_cast<std::size_t>(row) * width + col]) / max_value;
      const double occupancy = negate ? p : 1.0 - p;
      grid.set_occupied(col, height - 1 - row, occupancy > occupied_thresh);  // top row: largest y
    }
  }
  return grid;
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
