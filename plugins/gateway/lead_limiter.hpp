#pragma once
// How far a producer (the gateway of a run in one process, as fast as it goes) may run ahead of
// its consumers, stream by stream: samples written against samples the consumer processed. A
// sample lost on the way (a TOF past its lifespan, a sample pushed out of a full history) is
// never processed; once given up on it is counted as lost, so that it holds the producer back
// once, not at every later step (which turned a run with one lost sample into one that waited
// its give-up time at every 10 ms step: hours for a 30 s recording).
#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <vector>

namespace beaconloc {

class LeadLimiter {
 public:
  struct Stream {
    std::uint64_t written = 0;
    std::uint64_t processed = 0;
  };
  // The most samples each stream's consumer may lack (written, neither processed nor lost).
  explicit LeadLimiter(std::vector<std::uint64_t> max_lead)
      : max_lead_(max_lead), lost_(max_lead.size(), 0) {}

  // True while a stream's consumer lacks more than its lead. `now` holds one entry per stream.
  bool lagging(const std::vector<Stream>& now) const {
    for (std::size_t i = 0; i < now.size() && i < max_lead_.size(); ++i) {
      if (now[i].written > now[i].processed + lost_[i] + max_lead_[i]) return true;
    }
    return false;
  }
  // Gives up on what each consumer still lacks: lost, not waited for again. What it processes
  // later after all (a sample late, not lost) only loosens the limit by as much, for a while.
  void give_up(const std::vector<Stream>& now) {
    for (std::size_t i = 0; i < now.size() && i < lost_.size(); ++i) {
      lost_[i] = now[i].written - std::min(now[i].written, now[i].processed);
    }
  }
  // What stream i's consumer has not processed of what was written, less what was lost.
  std::uint64_t missing(std::size_t i, const Stream& now) const {
    const std::uint64_t accounted = now.processed + lost_[i];
    return now.written > accounted ? now.written - accounted : 0;
  }
  std::uint64_t lost(std::size_t i) const { return lost_[i]; }

 private:
  std::vector<std::uint64_t> max_lead_;
  std::vector<std::uint64_t> lost_;
};

}  // namespace beaconloc
