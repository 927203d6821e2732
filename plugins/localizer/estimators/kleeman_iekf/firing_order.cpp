#include "kleeman_iekf/firing_order.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "beaconloc/core/measurements.hpp"

namespace beaconloc::kleeman {

std::optional<PulseSlot> slot_of_pulse(double arrival_s, double t0_s, double period_s, double max_flight_s) {
  if (!std::isfinite(arrival_s) || !std::isfinite(t0_s) || !std::isfinite(period_s) || !std::isfinite(max_flight_s) ||
      !(period_s > 0.0) || !(max_flight_s > 0.0) || !(max_flight_s < period_s)) {
    return std::nullopt;
  }
  const double since_s = arrival_s - t0_s;
  if (since_s < 0.0) return PulseSlot{PulseSlot::Kind::kPast, 0};
  // Compared as a double before the conversion: a pulse years ahead must not overflow it.
  const double slot = std::floor(since_s / period_s);
  if (slot > static_cast<double>(kMaxSlotsAhead)) return PulseSlot{PulseSlot::Kind::kTooFarAhead, 0};
  const auto k = static_cast<std::int64_t>(slot);
  if (since_s - static_cast<double>(k) * period_s > max_flight_s) return PulseSlot{PulseSlot::Kind::kBetweenSlots, k};
  return PulseSlot{PulseSlot::Kind::kInSlot, k};
}

FiringOrder::FiringOrder(std::vector<std::uint32_t> order, std::uint32_t marked_beacon_id)
    : order_(std::move(order)) {
  if (order_.empty()) throw std::invalid_argument("firing order: no beacons");
  std::vector<std::uint32_t> sorted = order_;
  std::sort(sorted.begin(), sorted.end());
  if (std::adjacent_find(sorted.begin(), sorted.end()) != sorted.end()) {
    throw std::invalid_argument("firing order: a beacon fires twice in one cycle");
  }
  if (std::binary_search(sorted.begin(), sorted.end(), kBeaconUnidentified)) {
    throw std::invalid_argument("firing order: the unidentified beacon id is not a beacon");
  }
  const auto marked = std::find(order_.begin(), order_.end(), marked_beacon_id);
  if (marked == order_.end()) throw std::invalid_argument("firing order: the marked beacon does not fire in it");
  marked_index_ = marked - order_.begin();
}

FiringOrder::Pulse FiringOrder::heard(std::int64_t slot, bool double_burst) {
  if (last_heard_ && slot < *last_heard_) {
    ++out_of_order_pulses_;
    return Pulse::kOutOfOrder;
  }
  if (double_burst) {
    const std::optional<std::uint32_t> expected = beacon_of(slot);
    if (!expected) {
      sync_slot_ = slot;  // the first: it numbers the slots
    } else if (*expected != order_[static_cast<std::size_t>(marked_index_)]) {
      ++contradicting_double_bursts_;
      const auto n = static_cast<std::int64_t>(order_.size());
      if (contradicting_slot_ && slot != *contradicting_slot_ && (slot - *contradicting_slot_) % n == 0) {
        sync_slot_ = slot;  // confirmed a cycle (or more) later: the numbering was off
        ++resynchronizations_;
        contradicting_slot_.reset();
      } else {
        contradicting_slot_ = slot;
      }
    }
  }
  if (last_heard_ && slot == *last_heard_) {
    ++extra_pulses_;
    return Pulse::kExtraInSlot;
  }
  if (last_heard_) missed_slots_ += static_cast<std::uint64_t>(slot - *last_heard_ - 1);
  last_heard_ = slot;
  return Pulse::kFirstInSlot;
}

std::optional<std::uint32_t> FiringOrder::beacon_of(std::int64_t slot) const {
  if (!sync_slot_) return std::nullopt;
  const auto n = static_cast<std::int64_t>(order_.size());
  // The slot's place in the cycle, counted from the marked beacon's, for slots before the sync too.
  const std::int64_t index = ((marked_index_ + slot - *sync_slot_) % n + n) % n;
  return order_[static_cast<std::size_t>(index)];
}

}  // namespace beaconloc::kleeman
