#pragma once
// Which keys (robots) have been silent past their deadline: the DDS deadline QoS, kept by the
// reader itself. Fast DDS 2.9 looks through every instance of a keyed reader or writer with a
// deadline on each sample (the earliest deadline, to reschedule its timer), which made one sample
// cost O(robots) and wake the timer thread; this costs O(log robots) a sample and one pass over
// the keys per check (BENCHMARKS.md section 3). Pure: pushed each sample's arrival time, asked
// at times of its owner's choosing; it never reads a clock.
#include <cstdint>
#include <functional>
#include <map>
#include <stdexcept>

#include "beaconloc/core/time.hpp"

namespace beaconloc {

template <class Key, class Less = std::less<Key>>
class DeadlineWatch {
 public:
  // period_ns: how long a key may stay silent; throws std::invalid_argument unless > 0.
  explicit DeadlineWatch(StampNs period_ns) : period_ns_(period_ns) {
    if (period_ns <= 0) throw std::invalid_argument("a deadline period must be positive");
  }

  StampNs period_ns() const { return period_ns_; }

  // A sample of `key` arrived at now_ns: its next deadline is a period later. A key is watched
  // from its first sample on, until forgotten.
  void on_sample(const Key& key, StampNs now_ns) { next_deadline_ns_[key] = now_ns + period_ns_; }

  // Stops watching `key` until its next sample (its writer ended the instance, as the QoS stops
  // with an instance that is no longer alive).
  void forget(const Key& key) { next_deadline_ns_.erase(key); }

  // Calls on_missed(key) for each key whose deadline passed by now_ns, and moves its deadline
  // on by whole periods past now_ns; returns how many periods were missed in all (silent for
  // three periods since the last check: three misses, one call; so a process that stalled for
  // S seconds counts S / period misses for each key, where the QoS counted about one). Checked
  // more often than the period, a key silent for n periods gets n calls, one per period, as the
  // QoS's listener does.
  template <class OnMissed>
  std::uint64_t expire(StampNs now_ns, OnMissed&& on_missed) {
    std::uint64_t missed = 0;
    for (auto& [key, next_ns] : next_deadline_ns_) {
      if (next_ns > now_ns) continue;
      const std::uint64_t periods = static_cast<std::uint64_t>((now_ns - next_ns) / period_ns_) + 1;
      next_ns += static_cast<StampNs>(periods) * period_ns_;
      missed += periods;
      on_missed(key);
    }
    return missed;
  }

  std::size_t size() const { return next_deadline_ns_.size(); }

 private:
  StampNs period_ns_;
  std::map<Key, StampNs, Less> next_deadline_ns_;
};

}  // namespace beaconloc
