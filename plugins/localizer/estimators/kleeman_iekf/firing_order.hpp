#pragma once
// Which beacon a pulse came from (seed 002 Sec. 2, 3.5-3.7). The beacons fire in a fixed cycle
// (123456123...), one slot of T = 150 ms each, and a pulse carries no id, except that beacon 1
// fires a double burst. The filter holds T and t0, the firing time of its current slot (eq. 14;
// eq. 15 moves t0 on by T at each slot). A pulse belongs to the slot whose firing it follows by at
// most the longest flight (slot_of_pulse), and the beacon of a slot follows from the firing order,
// counted from the slot of the last double burst (FiringOrder). Slots are counted by time, not
// pulses by number: a missed pulse leaves its slot empty and an echo lands in a slot already heard
// (or between the listening windows), so neither shifts the numbering; both are counted.
#include <cstdint>
#include <optional>
#include <vector>

namespace beaconloc::kleeman {

// The most slots a pulse may lie ahead of the filter's current slot: 10 s of seed 002's 150 ms
// slots, after which a pose without a correction is lost anyway (StalenessPolicy). Through a
// shorter silence (an outage, a robot behind a pillar) the filter steps slot by slot on its dead
// reckoning, its uncertainty growing as it should; a pulse further ahead means the filter's t0
// or T is far off (or the pulse's stamp is), and the estimator starts again.
inline constexpr std::int64_t kMaxSlotsAhead = 67;

// Where a pulse heard at arrival_s falls against the slots t0_s + k period_s (k >= 0).
struct PulseSlot {
  enum class Kind {
    kInSlot,        // within max_flight_s after the firing of slot slots_ahead
    kBetweenSlots,  // later than the longest flight after any firing: no beacon sent it directly
    kPast,          // before the current slot's firing
    kTooFarAhead,   // more than kMaxSlotsAhead slots ahead
  };
  Kind kind = Kind::kInSlot;
  std::int64_t slots_ahead = 0;  // kInSlot: 0 for the current slot, k for the k-th after it
};

// nullopt when the numbers cannot place a pulse: not finite, period_s <= 0, or max_flight_s
// outside (0, period_s) (a flight as long as a slot would make the slots ambiguous).
std::optional<PulseSlot> slot_of_pulse(double arrival_s, double t0_s, double period_s, double max_flight_s);

// The beacons' firing order, and the slots heard so far. Slots are numbered by the estimator,
// one per firing, in time order (the estimator's current slot plus PulseSlot::slots_ahead).
class FiringOrder {
 public:
  // order: the beacon ids in firing order, each once; marked_beacon_id: the one in it that fires
  // a double burst. Throws std::invalid_argument otherwise (or on kBeaconUnidentified in it).
  FiringOrder(std::vector<std::uint32_t> order, std::uint32_t marked_beacon_id);

  enum class Pulse {
    kFirstInSlot,  // the slot's first pulse
    kExtraInSlot,  // the slot was heard already: an echo, or a stray (the gate decides)
    kOutOfOrder,   // a slot before the latest one heard: dropped, the filter has moved past it
  };
  // A pulse heard in `slot`, marked as a double burst or not. The first double burst sets the
  // numbering: the marked beacon fired in that slot. A later one where the numbering has another
  // beacon is counted (contradicting_double_bursts) but moves the numbering only when a second
  // confirms it a whole number of cycles later (re-synchronized, counted): an echo 3 ms behind a
  // single burst looks like a double burst (Fig. 2), and one such must not renumber every beacon.
  Pulse heard(std::int64_t slot, bool double_burst);

  // The beacon that fired in `slot`; nullopt before the first double burst.
  std::optional<std::uint32_t> beacon_of(std::int64_t slot) const;
  bool synchronized() const { return sync_slot_.has_value(); }

  // Slots between two heard ones with no pulse (a missed pulse each).
  std::uint64_t missed_slots() const { return missed_slots_; }
  std::uint64_t extra_pulses() const { return extra_pulses_; }
  std::uint64_t out_of_order_pulses() const { return out_of_order_pulses_; }
  // Double bursts heard in a slot the numbering gave to another beacon, and the times two of them
  // a whole number of cycles apart moved the numbering.
  std::uint64_t contradicting_double_bursts() const { return contradicting_double_bursts_; }
  std::uint64_t resynchronizations() const { return resynchronizations_; }

 private:
  std::vector<std::uint32_t> order_;
  std::int64_t marked_index_ = 0;           // of the marked beacon in order_
  std::optional<std::int64_t> sync_slot_;   // the slot of the last double burst
  std::optional<std::int64_t> last_heard_;  // the latest slot a pulse was heard in
  std::optional<std::int64_t> contradicting_slot_;  // the last double burst the numbering contradicted
  std::uint64_t missed_slots_ = 0;
  std::uint64_t extra_pulses_ = 0;
  std::uint64_t out_of_order_pulses_ = 0;
  std::uint64_t contradicting_double_bursts_ = 0;
  std::uint64_t resynchronizations_ = 0;
};

}  // namespace beaconloc::kleeman
