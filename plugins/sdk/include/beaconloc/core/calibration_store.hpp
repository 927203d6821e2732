#pragma once
// A site's beacon calibration (beacon_calibration.hpp) kept in a file, so that it survives a
// restart of every participant (issue 16). Written whole to a temporary of its own in the same
// directory (`<path>.tmp.XXXXXX`, mkstemp), flushed to the disk (fsync), renamed over `<path>`
// (atomic on POSIX), and the directory flushed: a process killed at any instant leaves the
// previous calibration or the new one, never a mix (a killed writer may leave its temporary
// behind; nothing reads it). Read back strictly: a version line, one line per group and per
// beacon, and a checksum line (FNV-1a 64 of every byte before it) that a torn file or an
// accidental change fails (it is no defence against a deliberate edit); every number parsed by
// core/decimal.hpp and the whole checked (check_calibration). Nothing is repaired.
//
//   beaconloc-calibration 1
//   group <id> <stamp_ns> <a> <b> <tx_m> <ty_m> <mean_error_m> <beacon count>
//   beacon <id> <x_m> <y_m> <z_m> <cov_xx_m2> <cov_xy_m2> <cov_yy_m2>
//   checksum <16 hex digits>
#include <cstdint>
#include <optional>
#include <string>

#include "beaconloc/core/beacon_calibration.hpp"

namespace beaconloc {

enum class CalibrationFileProblem : std::uint8_t {
  kNone,
  kMissing,           // no file at the path (no calibration kept yet)
  kUnreadable,        // it exists and cannot be read
  kTooLarge,          // longer than kMaxCalibrationFileBytes
  kMalformed,         // not the format above (detail: the line and what is wrong)
  kChecksumMismatch,  // the bytes are not the ones written (torn, edited)
  kInvalid,           // well formed, and check_calibration refuses it (detail: its reason)
  kWriteFailed,       // saving: a system call failed (detail: which, errno's text, and whether the
                      // new file is in place: only when the directory's flush failed)
};
const char* to_string(CalibrationFileProblem problem);

// Far beyond any site's calibration (kMaxBeacons beacons at ~150 bytes a line: 0.6 MB).
inline constexpr std::size_t kMaxCalibrationFileBytes = 4u << 20;

struct CalibrationFileResult {
  CalibrationFileProblem problem = CalibrationFileProblem::kNone;
  std::string detail;  // for people: the line, the system call
  bool ok() const { return problem == CalibrationFileProblem::kNone; }
};

// The calibration's text, checksum line included.
std::string format_calibration(const BeaconCalibration& calibration);
// The calibration a text holds, or nullopt with the reason in *result.
std::optional<BeaconCalibration> parse_calibration(const std::string& text, CalibrationFileResult* result);

// Refuses (kInvalid) a calibration check_calibration refuses: nothing is written then.
CalibrationFileResult save_calibration(const std::string& path, const BeaconCalibration& calibration);
std::optional<BeaconCalibration> load_calibration(const std::string& path, CalibrationFileResult* result);

}  // namespace beaconloc
