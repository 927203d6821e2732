#pragma once
// A reader whose topic must deliver (the beacon map: a decoder or localizer without it does
// nothing), recreated when it stays mute: for kMuteAfterNs without a single sample while there is
// a writer to hear, that is while it is matched, or while the peers are heard on other topics
// (the gateway's TOFs reach a decoder that has no map: the map's pair never matched). Fast DDS 2.9 leaves a secured writer-reader pair mute now and then (about 1 start in 20
// on a loaded machine: the key exchange of that one pair never completes, while the participants'
// other pairs work); a new reader is a new pair, whose exchange starts afresh, and the writer's
// transient-local history gives it the map. Each recreation is counted (recreated()).
#include <atomic>
#include <chrono>
#include <cstdint>
#include <functional>
#include <memory>
#include <mutex>

#include "beaconloc/dds/participant.hpp"
#include "beaconloc/dds/periodic_task.hpp"
#include "beaconloc/dds/wall_clock.hpp"

namespace beaconloc::dds {

// The Diagnostics reason a participant counts its beacon map reader's recreations under.
inline constexpr const char* kMapReaderRecreated = "beacon_map.reader_recreated";

class FirstSampleWatch {
 public:
  // The gateway writes its map at once on a match and again each second for 10 s: a working pair
  // delivers within a second or two. Three seconds without a sample is a mute pair.
  static constexpr std::int64_t kMuteAfterNs = 3'000'000'000;
  // A pair not matched at all while the peers are heard: secured discovery of one pair can take
  // several seconds on a loaded machine, and a new reader starts it again; so longer.
  static constexpr std::int64_t kUnmatchedAfterNs = 10'000'000'000;
  // make(heard): creates the reader; its callback calls heard() for every sample it takes.
  using Make = std::function<Reader(std::function<void()> heard)>;
  // peers_heard: whether the participant hears the peers that also write this topic (may be empty).
  explicit FirstSampleWatch(Make make, std::function<bool()> peers_heard = {})
      : make_(std::move(make)), peers_heard_(std::move(peers_heard)) {
    reader_ = make_([this] { heard_ = true; });
    checks_ = std::make_unique<PeriodicTask>(std::chrono::milliseconds(500), [this] { check(); });
  }
  ~FirstSampleWatch() {
    checks_.reset();  // no check runs after this
    std::lock_guard<std::mutex> lock(mutex_);
    reader_.reset();
  }
  FirstSampleWatch(const FirstSampleWatch&) = delete;
  FirstSampleWatch& operator=(const FirstSampleWatch&) = delete;
  std::uint64_t recreated() const { return recreated_.load(); }

 private:
  void check() {
    if (heard_) return;  // the pair works; later silence is the writer's, not the pair's
    std::lock_guard<std::mutex> lock(mutex_);
    eprosima::fastdds::dds::SubscriptionMatchedStatus status;
    reader_->get_subscription_matched_status(status);
    const std::int64_t now = steady_clock_ns();
    const bool matched = status.current_count > 0;
    if (!matched && !(peers_heard_ && peers_heard_())) {
      matched_since_ns_ = -1;  // nobody to hear yet: waiting is not muteness
      return;
    }
    if (matched_since_ns_ < 0) matched_since_ns_ = now;
    if (now - matched_since_ns_ < (matched ? kMuteAfterNs : kUnmatchedAfterNs)) return;
    reader_.reset();  // waits for a callback under way
    reader_ = make_([this] { heard_ = true; });
    matched_since_ns_ = -1;
    ++recreated_;
  }

  Make make_;
  std::function<bool()> peers_heard_;
  std::atomic<bool> heard_{false};
  std::atomic<std::uint64_t> recreated_{0};
  std::mutex mutex_;
  std::int64_t matched_since_ns_ = -1;  // since when there was a writer to hear
  Reader reader_;
  std::unique_ptr<PeriodicTask> checks_;  // last: stops before what it uses goes
};

}  // namespace beaconloc::dds
