// Faults injected into the simulated world (gateway/sim/faults.hpp): parsed from text or
// refused naming it; each silences exactly what it names and nothing else.
#include "sim/faults.hpp"

#include <gtest/gtest.h>

#include "offline_run.hpp"

namespace beaconloc::sim {
namespace {

std::string error_of(const std::string& spec) {
  Scenario s = default_scenario();
  try {
    apply_fault(s, spec);
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return {};
}

TEST(Faults, MalformedFaultsAreRefusedNamingThem) {
  for (const std::string bad : {"beacon_dies", "beacon_dies=1", "beacon_dies=x@3", "beacon_dies=1@-2",
                                "beacon_dies=99@3", "beacon_dies=1.5@3", "tof_outage=5", "tof_outage=5:4",
                                "tof_outage=a:b", "echoes=1.5", "echoes=nan", "meteor=1", ""}) {
    const std::string e = error_of(bad);
    EXPECT_NE(e.find("fault '" + bad + "'"), std::string::npos) << bad << ": " << e;
  }
  EXPECT_EQ(error_of("beacon_dies=1@3"), "");
  EXPECT_EQ(error_of("tof_outage=2.5:4"), "");
  EXPECT_EQ(error_of("echoes=0.3"), "");
}

TEST(Faults, EachFaultSilencesWhatItNamesAndTheNoiseStaysTheSame) {
  Scenario clean = default_scenario();
  Scenario faulty = clean;
  const std::uint32_t dead = clean.beacons.front().id;
  apply_fault(faulty, "beacon_dies=" + std::to_string(dead) + "@4");
  apply_fault(faulty, "tof_outage=8:10");
  const auto before = simulate(clean, 7, 14.0);
  const auto after = simulate(faulty, 7, 14.0);
  std::size_t odometry_before = 0, odometry_after = 0, tofs_kept = 0;
  for (const auto& e : before) odometry_before += e.kind == SourceEvent::Kind::kOdometry;
  for (const auto& e : after) {
    if (e.kind == SourceEvent::Kind::kOdometry) ++odometry_after;
    if (e.kind != SourceEvent::Kind::kTof) continue;
    const double fire_s = ns_to_s(e.tof.fire_stamp_ns);
    EXPECT_FALSE(e.true_beacon_id == dead && fire_s >= 4.0) << fire_s;
    EXPECT_FALSE(fire_s >= 8.0 && fire_s < 10.0) << fire_s;
    // Every TOF left is the clean run's, to the bit.
    const auto same = std::find_if(before.begin(), before.end(), [&](const SourceEvent& b) {
      return b.kind == SourceEvent::Kind::kTof && b.tof.fire_stamp_ns == e.tof.fire_stamp_ns &&
             b.tof.receiver_id == e.tof.receiver_id;
    });
    ASSERT_NE(same, before.end());
    EXPECT_EQ(same->tof.tof_s, e.tof.tof_s);
    ++tofs_kept;
  }
  EXPECT_EQ(odometry_after, odometry_before);  // the robot's odometry goes on
  EXPECT_GT(tofs_kept, 100u);
}

}  // namespace
}  // namespace beaconloc::sim
