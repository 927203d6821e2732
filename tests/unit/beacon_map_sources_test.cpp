// Two live writers of the beacon map that disagree are a conflict to report (issue 23), not a
// map to flip to silently; it ends when one leaves or they agree. DDS-free.
#include <gtest/gtest.h>

#include "beaconloc/core/beacon_map_sources.hpp"
#include "sim/scenario.hpp"

namespace beaconloc {
namespace {

TEST(BeaconMapSources, WritersThatPublishDifferentMapsDisagreeUntilOneLeavesOrTheyAgree) {
  const BeaconMap site(sim::default_scenario().beacons);
  std::vector<Beacon> moved_beacons = sim::default_scenario().beacons;
  moved_beacons.front().position_map_m.x() += 0.5;
  const BeaconMap moved(moved_beacons);
  BeaconMapSources sources;
  EXPECT_EQ(sources.distinct_maps(), 0u);
  sources.on_map("gateway_a", site);
  EXPECT_EQ(sources.distinct_maps(), 1u);
  sources.on_map("gateway_b", site);  // a second gateway with the same map: no conflict
  EXPECT_EQ(sources.distinct_maps(), 1u);
  ASSERT_TRUE(sources.agreed_map());
  EXPECT_EQ(*sources.agreed_map(), site);
  sources.on_map("gateway_b", moved);
  EXPECT_EQ(sources.distinct_maps(), 2u);
  EXPECT_TRUE(sources.disagree());
  EXPECT_FALSE(sources.agreed_map());
  EXPECT_EQ(sources.describe(), "2 writers publish 2 different beacon maps");
  sources.on_map("gateway_b", site);  // it agrees again
  EXPECT_EQ(sources.distinct_maps(), 1u);
  sources.on_map("gateway_c", moved);
  EXPECT_EQ(sources.distinct_maps(), 2u);
  sources.on_writer_gone("gateway_a");
  sources.on_writer_gone("gateway_b");
  EXPECT_EQ(sources.distinct_maps(), 1u);  // the one left: its map is agreed
  ASSERT_TRUE(sources.agreed_map());
  EXPECT_EQ(*sources.agreed_map(), moved);
  sources.on_writer_gone("gateway_c");
  EXPECT_EQ(sources.distinct_maps(), 0u);
  EXPECT_FALSE(sources.agreed_map());
  // A gone writer's last map told after its leaving (two threads) does not bring it back.
  sources.on_map("gateway_d", site);
  sources.on_map("gateway_a", moved);
  EXPECT_FALSE(sources.disagree());
  ASSERT_TRUE(sources.agreed_map());
  EXPECT_EQ(*sources.agreed_map(), site);
}

}  // namespace
}  // namespace beaconloc
