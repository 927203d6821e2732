#include "beaconloc/core/csv_reader.hpp"

#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <iomanip>
#include <set>
#include <sstream>

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

bool parse_finite(const std::string& cell, double& out) {
  if (cell.empty()) return false;
  errno = 0;
  char* end = nullptr;
  out = std::strtod(cell.c_str(), &end);
  return errno == 0 && end == cell.c_str() + cell.size() && std::isfinite(out);
}

bool parse_id(const std::string& cell, std::uint32_t& out) {
  double v = 0.0;
  if (!parse_finite(cell, v) || v < 0.0 || v >= 4294967295.0 || v != std::floor(v)) return false;
  out = static_cast<std::uint32_t>(v);
  return true;
}

CsvReader::CsvReader(const std::string& path, const std::vector<std::string>& required)
    : path_(path), in_(path) {
  if (!in_) throw CsvError("cannot read '" + path + "'");
  std::string header;
  if (!std::getline(in_, header)) throw CsvError(path + ":1: empty file, expected a header row");
  const auto names = split_csv_line(strip(header));
  for (std::size_t i = 0; i < names.size(); ++i) columns_[names[i]] = i;
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

BeaconMap load_beacon_map_csv(const std::string& path) {
  CsvReader csv(path, {"beacon_id", "x_m", "y_m", "z_m"});
  std::vector<Beacon> beacons;
  std::set<std::uint32_t> ids;
  while (csv.next()) {
    Beacon b;
    double x = 0, y = 0, z = 0;
    if (!csv.complete() || !parse_id(csv.cell("beacon_id"), b.id) || !parse_finite(csv.cell("x_m"), x) ||
        !parse_finite(csv.cell("y_m"), y) || !parse_finite(csv.cell("z_m"), z)) {
      throw CsvError(csv.where() + ": malformed beacon row");
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
