// Fuzz target: what `beaconloc eval` reads (plugins/eval/evaluation.cpp, the CSV readers of
// plugins/sdk/src/csv_reader.cpp): truth.csv, estimate.csv and beacons.csv, separated by lines
// "%%" (no third part: no beacons file). Each must load or throw CsvError; what loads is scored
// and plotted as the command does (metrics, error series, SVGs into a scratch directory). Any
// other exception, a crash, undefined behaviour or a hang is a bug.
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "beaconloc/core/csv_reader.hpp"
#include "evaluation.hpp"
#include "fuzz_files.hpp"
#include "svg_plot.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace beaconloc;
  const auto parts = fuzz::split_parts(data, size);
  const auto& dir = fuzz::scratch_dir();
  fuzz::write_or_remove(dir / "truth.csv", parts, 0);
  fuzz::write_or_remove(dir / "estimate.csv", parts, 1);
  fuzz::write_or_remove(dir / "beacons.csv", parts, 2);
  TruthTrack truth;
  std::vector<EstimateRow> rows;
  BeaconMap beacons;
  try {
    truth = load_truth_csv((dir / "truth.csv").string());
    rows = load_estimates_csv((dir / "estimate.csv").string());
    if (parts.size() > 2) beacons = load_beacon_map_csv((dir / "beacons.csv").string());
  } catch (const CsvError&) {
    return 0;
  }
  const Metrics m = evaluate(truth, rows);
  if (m.samples + m.samples_without_truth > rows.size()) __builtin_trap();
  const auto errors = error_series(truth, rows);
  write_trajectory_svg((dir / "trajectory.svg").string(), "fuzz", truth, rows, beacons);
  write_error_svg((dir / "error.svg").string(), "fuzz", errors);
  return 0;
}
