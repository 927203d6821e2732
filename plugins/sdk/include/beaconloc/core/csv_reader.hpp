#pragma once
// Reading the project's CSV files (replayed recordings, truth, estimates, beacon maps): a header
// row names the columns, found by name; numbers are whole cells read by core/decimal.hpp's
// parser. A UTF-8 byte order mark before the header (spreadsheets write one) is an encoding
// mark, not part of the first column's name: it is skipped.
#include <cstdint>
#include <fstream>
#include <map>
#include <stdexcept>
#include <string>
#include <vector>

#include "beaconloc/core/beacon_map.hpp"
#include "beaconloc/core/decimal.hpp"

namespace beaconloc {

class CsvError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

class CsvReader {
 public:
  // Throws CsvError naming the file when it cannot be read, or the header lacks a column or
  // names one twice.
  CsvReader(const std::string& path, const std::vector<std::string>& required_columns);
  // Next non-blank row; false at the end.
  bool next();
  const std::vector<std::string>& cells() const { return cells_; }
  bool complete() const { return cells_.size() == width_; }  // as many cells as the header
  // "3 cells, the header has 4": why a row is not complete().
  std::string cell_count_problem() const {
    return std::to_string(cells_.size()) + " cells, the header has " + std::to_string(width_);
  }
  bool has_column(const std::string& name) const { return columns_.count(name) > 0; }
  const std::string& cell(const std::string& column) const { return cells_.at(columns_.at(column)); }
  // The cell of `column` as a number within [min, max] (an id: not 0xFFFFFFFF, kept for
  // unidentified beacons). The error says which test failed (kNotDecimal: not a number at all);
  // `problem` then names the column and the cell: "v_mps '0x1p1' is not a decimal number",
  // "t_s -1 is outside [0, 4.6e+09]".
  NumberError read(const std::string& column, double& out, double min, double max,
                   std::string& problem) const;
  NumberError read(const std::string& column, std::int64_t& out, std::int64_t min, std::int64_t max,
                   std::string& problem) const;
  NumberError read_id(const std::string& column, std::uint32_t& out, std::string& problem) const;
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

// beacon_id,x_m,y_m,z_m, optional group (its beacon group, 0 by default) and frame (map, the
// default; or group: a locally referenced beacon, x, y in its group's frame, seed 003). Throws
// CsvError naming the file and line of a malformed row (the column and the cell: a position must
// lie within kMaxMapCoordinateM, core/limits.hpp), a repeated id, a frame neither map nor group,
// a local beacon without a group, a group of both kinds, or a file without beacons.
BeaconMap load_beacon_map_csv(const std::string& path);
// Written whole or not at all (a temporary file renamed over it): a kill never leaves half a map.
void write_beacon_map_csv(const std::string& path, const BeaconMap& map);
// text into path, through a temporary file beside it renamed over it. Throws CsvError.
void write_file_atomically(const std::string& path, const std::string& text);

}  // namespace beaconloc
