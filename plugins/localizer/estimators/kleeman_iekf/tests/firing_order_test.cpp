// Beacon identification from the firing order (seed 002 Sec. 2, 3.5-3.7; issue 15 item 2): a
// pulse's slot from the filter's t0 and T, the beacon of a slot from the last double burst, and a
// missed pulse, an extra echo, a late pulse and a contradicting double burst each counted without
// shifting the numbering.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <stdexcept>

#include "beaconloc/core/measurements.hpp"
#include "kleeman_iekf/firing_order.hpp"

namespace beaconloc::kleeman {
namespace {

constexpr double kPeriodS = 0.15;     // seed 002 Sec. 2
constexpr double kMaxFlightS = 0.06;  // 20 m at 340 m/s (the scenario's max_range_m)

TEST(SlotOfPulse, APulseBelongsToTheSlotWhoseFiringItFollowsByAtMostTheLongestFlight) {
  const double t0 = 100.0;
  auto slot = slot_of_pulse(t0 + 0.02, t0, kPeriodS, kMaxFlightS);
  ASSERT_TRUE(slot);
  EXPECT_EQ(slot->kind, PulseSlot::Kind::kInSlot);
  EXPECT_EQ(slot->slots_ahead, 0);
  slot = slot_of_pulse(t0 + 3 * kPeriodS + 0.035, t0, kPeriodS, kMaxFlightS);
  ASSERT_TRUE(slot);
  EXPECT_EQ(slot->kind, PulseSlot::Kind::kInSlot);
  EXPECT_EQ(slot->slots_ahead, 3);
  // 100 ms after a firing: longer than any direct flight, and before the next firing.
  slot = slot_of_pulse(t0 + kPeriodS + 0.1, t0, kPeriodS, kMaxFlightS);
  ASSERT_TRUE(slot);
  EXPECT_EQ(slot->kind, PulseSlot::Kind::kBetweenSlots);
  slot = slot_of_pulse(t0 - 0.001, t0, kPeriodS, kMaxFlightS);
  ASSERT_TRUE(slot);
  EXPECT_EQ(slot->kind, PulseSlot::Kind::kPast);
}

TEST(SlotOfPulse, APulseFarAheadOrNumbersThatCannotPlaceOneAreSaidSo) {
  const auto far = slot_of_pulse(1e15, 0.0, kPeriodS, kMaxFlightS);  // no overflow, no long loop
  ASSERT_TRUE(far);
  EXPECT_EQ(far->kind, PulseSlot::Kind::kTooFarAhead);
  const auto last = slot_of_pulse((kMaxSlotsAhead + 0.1) * kPeriodS, 0.0, kPeriodS, kMaxFlightS);
  ASSERT_TRUE(last);
  EXPECT_EQ(last->kind, PulseSlot::Kind::kInSlot);
  EXPECT_EQ(last->slots_ahead, kMaxSlotsAhead);
  const double nan = std::numeric_limits<double>::quiet_NaN(), inf = std::numeric_limits<double>::infinity();
  EXPECT_FALSE(slot_of_pulse(nan, 0.0, kPeriodS, kMaxFlightS));
  EXPECT_FALSE(slot_of_pulse(0.1, inf, kPeriodS, kMaxFlightS));
  EXPECT_FALSE(slot_of_pulse(0.1, 0.0, 0.0, kMaxFlightS));
  EXPECT_FALSE(slot_of_pulse(0.1, 0.0, -kPeriodS, kMaxFlightS));
  EXPECT_FALSE(slot_of_pulse(0.1, 0.0, kPeriodS, kPeriodS));  // a flight as long as a slot
  EXPECT_FALSE(slot_of_pulse(0.1, 0.0, kPeriodS, 0.0));
}

TEST(FiringOrder, TheDoubleBurstNumbersTheSlotsBothWays) {
  FiringOrder order({1, 2, 3, 4, 5, 6}, 1);
  EXPECT_EQ(order.heard(0, false), FiringOrder::Pulse::kFirstInSlot);
  EXPECT_FALSE(order.synchronized());
  EXPECT_FALSE(order.beacon_of(0));
  EXPECT_EQ(order.heard(3, true), FiringOrder::Pulse::kFirstInSlot);  // beacon 1 fired in slot 3
  ASSERT_TRUE(order.synchronized());
  EXPECT_EQ(*order.beacon_of(3), 1u);
  EXPECT_EQ(*order.beacon_of(4), 2u);
  EXPECT_EQ(*order.beacon_of(8), 6u);
  EXPECT_EQ(*order.beacon_of(9), 1u);
  EXPECT_EQ(*order.beacon_of(2), 6u);  // slots before the double burst too
  EXPECT_EQ(*order.beacon_of(0), 4u);
  EXPECT_EQ(*order.beacon_of(-4), 6u);
}

TEST(FiringOrder, TheMarkedBeaconNeedNotFireFirst) {
  FiringOrder order({7, 9, 4}, 4);
  order.heard(10, true);
  EXPECT_EQ(*order.beacon_of(10), 4u);
  EXPECT_EQ(*order.beacon_of(11), 7u);
  EXPECT_EQ(*order.beacon_of(12), 9u);
}

TEST(FiringOrder, AMissedPulseAndAnExtraEchoAreCountedAndShiftNothing) {
  FiringOrder order({1, 2, 3, 4, 5, 6}, 1);
  order.heard(0, true);
  order.heard(1, false);
  // Slot 2's pulse is missed: slot 3 is still beacon 4.
  EXPECT_EQ(order.heard(3, false), FiringOrder::Pulse::kFirstInSlot);
  EXPECT_EQ(order.missed_slots(), 1u);
  EXPECT_EQ(*order.beacon_of(3), 4u);
  // An echo in slot 3: counted, the numbering as it was.
  EXPECT_EQ(order.heard(3, false), FiringOrder::Pulse::kExtraInSlot);
  EXPECT_EQ(order.extra_pulses(), 1u);
  EXPECT_EQ(order.heard(4, false), FiringOrder::Pulse::kFirstInSlot);
  EXPECT_EQ(*order.beacon_of(4), 5u);
  // Two cycles missed: still numbered by time.
  EXPECT_EQ(order.heard(17, false), FiringOrder::Pulse::kFirstInSlot);
  EXPECT_EQ(order.missed_slots(), 13u);
  EXPECT_EQ(*order.beacon_of(17), 6u);
  EXPECT_EQ(order.resynchronizations(), 0u);
}

TEST(FiringOrder, APulseForASlotAlreadyPassedIsDroppedAndCounted) {
  FiringOrder order({1, 2, 3, 4, 5, 6}, 1);
  order.heard(5, false);
  EXPECT_EQ(order.heard(4, true), FiringOrder::Pulse::kOutOfOrder);
  EXPECT_EQ(order.out_of_order_pulses(), 1u);
  EXPECT_FALSE(order.synchronized());  // a late double burst does not number the slots
}

TEST(FiringOrder, DoubleBurstsWhereTheNumberingSaysAnotherBeaconResynchronizeOnlyWhenTwoAgree) {
  FiringOrder order({1, 2, 3, 4, 5, 6}, 1);
  order.heard(0, true);
  order.heard(6, true);  // as the numbering says: not a contradiction
  EXPECT_EQ(order.contradicting_double_bursts(), 0u);
  order.heard(13, true);  // the numbering says beacon 2: an echo behind a single burst, or an error
  EXPECT_EQ(order.contradicting_double_bursts(), 1u);
  EXPECT_EQ(order.resynchronizations(), 0u);
  EXPECT_EQ(*order.beacon_of(13), 2u);  // one mark does not renumber every beacon
  order.heard(17, true);                // another, out of phase with the first: still not
  EXPECT_EQ(order.resynchronizations(), 0u);
  order.heard(23, true);  // a cycle after the last: the slots were off by five
  EXPECT_EQ(order.contradicting_double_bursts(), 3u);
  EXPECT_EQ(order.resynchronizations(), 1u);
  EXPECT_EQ(*order.beacon_of(23), 1u);
  EXPECT_EQ(*order.beacon_of(24), 2u);
}

TEST(FiringOrder, AnOrderThatCannotNumberTheSlotsIsRefused) {
  EXPECT_THROW(FiringOrder({}, 1), std::invalid_argument);
  EXPECT_THROW(FiringOrder({1, 2, 2}, 1), std::invalid_argument);
  EXPECT_THROW(FiringOrder({1, 2, 3}, 4), std::invalid_argument);
  EXPECT_THROW(FiringOrder({1, kBeaconUnidentified}, 1), std::invalid_argument);
}

}  // namespace
}  // namespace beaconloc::kleeman
