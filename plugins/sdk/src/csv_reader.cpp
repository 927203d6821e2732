#include "beaconloc/core/csv_reader.hpp"

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <iomanip>
#include <limits>
#include <set>
#include <sstream>

#include "beaconloc/core/limits.hpp"

namespace beaconloc {
namespace {

std::string strip(std::string s) {
  while (!s.empty() && (s.back() == '\r' || s.back() == ' ' || s.back() == '\t')) s.pop_back();
  return s;
}

}  // namespace

std::vector<std::string> split_csv_line(const std::string& line) {
  std::vector<std::string> out;
  std::stringstream ss(line);
  std::string cell;
  while (std::getline(ss, cell, ',')) out.push_back(cell);
  if (!line.empty() && line.back() == ',') out.emplace_back();
  return out;
}

CsvReader::CsvReader(const std::string& path, const std::vector<std::string>& required)
    : path_(path), in_(path) {
  if (!in_) throw CsvError("cannot read '" + path + "'");
  std::string header;
  if (!std::getline(in_, header)) throw CsvError(path + ":1: empty file, expected a header row");
  const std::string bom = "\xEF\xBB\xBF";
  if (header.compare(0, bom.size(), bom) == 0) header.erase(0, bom.size());
  const auto names = split_csv_line(strip(header));
  for (std::size_t i = 0; i < names.size(); ++i) {
    if (!columns_.emplace(names[i], i).second)
      throw CsvError(path + ":1: header names column '" + names[i] + "' twice");
  }
  for (const auto& r : required) {
    if (!columns_.count(r)) throw CsvError(path + ":1: header lacks column '" + r + "'");
  }
  width_ = names.size();
}

bool CsvReader::next() {
  std::string line;
  while (std::getline(in_, line)) {
    ++line_;
    line = strip(line);
    if (line.empty()) continue;
    cells_ = split_csv_line(line);
    return true;
  }
  return false;
}

NumberError CsvReader::read(const std::string& column, double& out, double min, double max,
                            std::string& problem) const {
  const std::string& text = cell(column);
  NumberError e = parse_decimal(text, out);
  if (e != NumberError::kNone) {
    problem = number_problem(column, text, e);
  } else if (!(out >= min && out <= max)) {
    e = NumberError::kOutOfRange;
    problem = range_problem(column, out, min, max);
  }
  return e;
}

NumberError CsvReader::read(const std::string& column, std::int64_t& out, std::int64_t min, std::int64_t max,
                            std::string& problem) const {
  const std::string& text = cell(column);
  NumberError e = parse_decimal(text, out);
  if (e != NumberError::kNone) {
    problem = number_problem(column, text, e);
  } else if (out < min || out > max) {
    e = NumberError::kOutOfRange;
    problem = column + " " + text + " is outside [" + std::to_string(min) + ", " + std::to_string(max) + "]";
  }
  return e;
}

NumberError CsvReader::read_id(const std::string& column, std::uint32_t& out, std::string& problem) const {
  const std::string& text = cell(column);
  NumberError e = parse_decimal(text, out);
  if (e == NumberError::kNone && out == std::numeric_limits<std::uint32_t>::max()) {
    e = NumberError::kOutOfRange;  // the id of unidentified pulses
  }
  if (e != NumberError::kNone) problem = number_problem(column, text, e) + " (an id in 0..4294967294)";
  return e;
}

BeaconMap load_beacon_map_csv(const std::string& path) {
  CsvReader csv(path, {"beacon_id", "x_m", "y_m", "z_m"});
  const bool has_group = csv.has_column("group"), has_frame = csv.has_column("frame");
  BeaconList beacons;
  std::set<std::uint32_t> ids;
  while (csv.next()) {
    std::uint32_t id = 0, group = 0;
    double x = 0, y = 0, z = 0;
    std::string problem;
    if (!csv.complete()) throw CsvError(csv.where() + ": malformed beacon row: " + csv.cell_count_problem());
    if (csv.read_id("beacon_id", id, problem) != NumberError::kNone ||
        csv.read("x_m", x, -kMaxMapCoordinateM, kMaxMapCoordinateM, problem) != NumberError::kNone ||
        csv.read("y_m", y, -kMaxMapCoordinateM, kMaxMapCoordinateM, problem) != NumberError::kNone ||
        csv.read("z_m", z, -kMaxMapCoordinateM, kMaxMapCoordinateM, problem) != NumberError::kNone ||
        (has_group && csv.read_id("group", group, problem) != NumberError::kNone)) {
      throw CsvError(csv.where() + ": malformed beacon row: " + problem);
    }
    if (!ids.insert(id).second)
      throw CsvError(csv.where() + ": beacon id " + std::to_string(id) + " repeated");
    const std::string frame = has_frame ? csv.cell("frame") : "map";
    if (frame == "map") {
      beacons.map_frame.push_back({id, {x, y, z}, group});
    } else if (frame == "group") {
      beacons.group_frame.push_back({id, group, {x, y, z}});  // group 0: check_beacons refuses it below
    } else {
      throw CsvError(csv.where() + ": malformed beacon row: frame '" + frame + "' is neither map nor group");
    }
  }
  if (beacons.map_frame.empty() && beacons.group_frame.empty()) throw CsvError(path + ": no beacons");
  const BeaconMapCheck check = check_beacons(beacons);
  if (!check.ok()) throw CsvError(path + ": " + check.describe());
  return BeaconMap(beacons);
}

void write_file_atomically(const std::string& path, const std::string& text) {
  // Written beside it, then renamed over it: a reader, or a kill, sees the old file or the new.
  const std::string temporary = path + ".tmp";
  {
    std::ofstream out(temporary, std::ios::trunc);
    if (!out) throw CsvError("cannot write '" + temporary + "'");
    if (!(out << text).flush()) throw CsvError("writing '" + temporary + "' failed");
  }
  if (std::rename(temporary.c_str(), path.c_str()) != 0) {
    throw CsvError("cannot rename '" + temporary + "' to '" + path + "': " + std::strerror(errno));
  }
}

void write_beacon_map_csv(const std::string& path, const BeaconMap& map) {
  // Positions as the shortest text that reads back to the same double: a map read again is the map.
  std::string text = "beacon_id,x_m,y_m,z_m,group,frame\n";
  const auto row = [&text](std::uint32_t id, const Eigen::Vector3d& p, std::uint32_t group, const char* frame) {
    text += std::to_string(id);
    for (int i = 0; i < 3; ++i) {
      text += ',';
      append_decimal(text, p(i));
    }
    text += ',' + std::to_string(group) + ',' + frame + '\n';
  };
  for (const auto& b : map.beacons()) row(b.id, b.position_map_m, b.group, "map");
  for (const auto& b : map.local_beacons()) row(b.id, b.position_group_m, b.group, "group");
  write_file_atomically(path, text);
}

}  // namespace beaconloc
