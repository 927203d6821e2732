// Fuzz target: the replay of a recording of the bus (plugins/gateway/replay/replay_bus_recording.cpp;
// docs/replay-format.md, "Recordings of the bus"). Input: beacons.csv, odometry.csv, tof.csv,
// pulse.csv, scan.csv, receivers.csv and truth.csv, separated by lines "%%" (a part that is empty
// or missing is an absent file). The recording must load or throw ReplayError; a row that is no
// sample is refused and counted, never a crash, undefined behaviour, a hang or another exception.
// What loads replays every event in stamp order, each TOF arriving at its fire stamp plus its TOF.
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
  fuzz::write_recording(parts, {"beacons.csv", "odometry.csv", "tof.csv", "pulse.csv", "scan.csv",
                                "receivers.csv", "truth.csv"});
  std::unique_ptr<ReplaySource> replay;
  try {
    replay = std::make_unique<ReplaySource>(dir.string());
  } catch (const ReplayError&) {
    return 0;
  }
  check(replay->receivers().size() > 0);
  std::vector<SourceEvent> events;
  replay->advance(replay->last_stamp_ns(), events);
  check(events.size() == replay->event_count() && replay->exhausted());
  for (std::size_t i = 0; i < events.size(); ++i) {
    if (i) check(events[i - 1].stamp_ns <= events[i].stamp_ns);
    if (events[i].kind == SourceEvent::Kind::kTof) {
      check(events[i].stamp_ns == events[i].tof.fire_stamp_ns + s_to_ns(events[i].tof.tof_s));
    }
  }
  return 0;
}
