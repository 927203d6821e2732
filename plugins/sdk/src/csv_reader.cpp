#include "beaconloc/core/csv_reader.hpp"

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
  std::vector<Beacon> beacons;
  std::set<std::uint32_t> ids;
  while (csv.next()) {
    Beacon b;
    double x = 0, y = 0, z = 0;
    std::string problem;
    if (!csv.complete()) throw CsvError(csv.where() + ": malformed beacon row: " + csv.cell_count_problem());
    if (csv.read_id("beacon_id", b.id, problem) != NumberError::kNone ||
        csv.read("x_m", x, -kMaxMapCoordinateM, kMaxMapCoordinateM, problem) != NumberError::kNone ||
        csv.read("y_m", y, -kMaxMapCoordinateM, kMaxMapCoordinateM, problem) != NumberError::kNone ||
        csv.read("z_m", z, -kMaxMapCoordinateM, kMaxMapCoordinateM, problem) != NumberError::kNone) {
      throw CsvError(csv.where() + ": malformed beacon row: " + problem);
    }
    if (!ids.insert(b.id).second)
      throw CsvError(csv.where() + ": beacon id " + std::to_string(b.id) + " repeated");
    b.position_map_m = {x, y, z};
    beacons.push_back(b);
  }
  if (beacons.empty()) throw CsvError(path + ": no beacons");
  return BeaconMap(beacons);
}

void write_beacon_map_csv(const std::string& path, const BeaconMap& map) {
  std::ofstream out(path);
  if (!out) throw CsvError("cannot write '" + path + "'");
  out << "beacon_id,x_m,y_m,z_m\n" << std::setprecision(10);
  for (const auto& b : map.beacons()) {
    out << b.id << ',' << b.position_map_m.x() << ',' << b.position_map_m.y() << ',' << b.position_map_m.z()
        << '\n';
  }
  if (!out.flush()) throw CsvError("writing '" + path + "' failed");
}

}  // namespace beaconloc
