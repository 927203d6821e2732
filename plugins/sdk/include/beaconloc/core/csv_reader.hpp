#pragma once
// Reading the project's CSV files (replayed recordings, truth, estimates, beacon maps): a header
// row names the columns, found by name; numbers must be whole cells and finite.
#include <cstdint>
#include <fstream>
#include <map>
#include <stdexcept>
#include <string>
#include <vector>

#include "beaconloc/core/beacon_map.hpp"

namespace beaconloc {

class CsvError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

class CsvReader {
 public:
  // Throws CsvError naming the file when it cannot be read or the header lacks a column.
  CsvReader(const std::string& path, const std::vector<std::string>& required_columns);
  // Next non-blank row; false at the end.
  bool next();
  const std::vector<std::string>& cells() const { return cells_; }
  bool complete() const { return cells_.size() == width_; }  // as many cells as the header
  bool has_column(const std::string& name) const { return columns_.count(name) > 0; }
  const std::string& cell(const std::string& column) const { return cells_.at(columns_.at(column)); }
  std::size_t line() const { return line_; }  // of the row last read; the header is line 1
  std::size_t width() const { return width_; }
  // "path:line" of the row last read, for messages.
  std::string where() const { return path_ + ":" + std::to_string(line_); }

 private:
  std::string path_;
  std::ifstream in_;
  std::map<std::string, std::size_t> columns_;
  std::vector<std::string> cells_;
  std::size_t width_ = 0;
  std::size_t line_ = 1;
};

std::vector<std::string> split_csv_line(const std::string& line);
// A finite number filling the whole cell.
bool parse_finite(const std::string& cell, double& out);
// An unsigned 32-bit id (not 0xFFFFFFFF, kept for unidentified beacons) filling the whole cell.
bool parse_id(const std::string& cell, std::uint32_t& out);

// beacon_id,x_m,y_m,z_m. Throws CsvError naming the file and line of a malformed row, a repeated
// id, or a file without beacons.
BeaconMap load_beacon_map_csv(const std::string& path);
void write_beacon_map_csv(const std::string& path, const BeaconMap& map);

}  // namespace beaconloc
