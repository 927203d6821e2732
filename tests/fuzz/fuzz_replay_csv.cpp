// Fuzz target: the replay readers (plugins/gateway/replay/replay_source.cpp over
// plugins/sdk/src/csv_reader.cpp; format in docs/replay-format.md). Input: beacons.csv, odom.csv,
// ranges.csv, gt.csv and pulses.csv, separated by lines "%%" (a file the input lacks, or whose
// part is empty, is absent). The
// recording must load or throw ReplayError; a bad row is refused and counted, never a crash,
// undefined behaviour, a hang or another exception type. What loads must replay: every event,
// in stamp order.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "fuzz_files.hpp"
#include "replay/replay_source.hpp"

namespace {

void check(bool ok) {
  if (!ok) __builtin_trap();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace beaconloc;
  const auto parts = fuzz::split_parts(data, size);
  const auto& dir = fuzz::scratch_dir();
  fuzz::write_recording(parts, {"beacons.csv", "odom.csv", "ranges.csv", "gt.csv", "pulses.csv"});
  std::unique_ptr<ReplaySource> replay;
  try {
    replay = std::make_unique<ReplaySource>(dir.string());
  } catch (const ReplayError&) {
    return 0;
  }
  check(!replay->beacon_map().empty());
  check(replay->event_count() > 0);
  std::vector<SourceEvent> events;
  replay->advance(replay->last_stamp_ns(), events);
  check(events.size() == replay->event_count() && replay->exhausted());
  for (std::size_t i = 0; i < events.size(); ++i) {
    const SourceEvent& e = events[i];
    check(i == 0 || events[i - 1].stamp_ns <= e.stamp_ns);
    switch (e.kind) {
      case SourceEvent::Kind::kOdometry:
        check(e.odometry.stamp_ns == e.stamp_ns && e.odometry.wheel_base_m > 0.0);
        break;
      case SourceEvent::Kind::kTof:
        check(std::isfinite(e.tof.tof_s));
        break;
      case SourceEvent::Kind::kPulse:
        check(e.pulse.stamp_ns == e.stamp_ns && e.stamp_ns >= 0);
        break;
      case SourceEvent::Kind::kTruth:
        check(e.truth_map_base.allFinite());
        break;
      default:
        break;
    }
  }
  return 0;
}
