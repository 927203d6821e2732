#pragma once
// localizer participant: Odometry + BeaconRange (+ BeaconMap) -> PoseEstimate, through the
// LocalizerCore (one estimator plugin instance per robot); Diagnostics at 1 Hz, listing the robots
// it serves. The site's beacon calibration (seed 003) goes both ways on BeaconCalibration: what
// its robots calibrate is published and kept in the calibration file, what others calibrated is
// used by its robots. It reads the other participants' Diagnostics, not their poses: a robot another live
// localizer serves too is a conflict (ServingConflicts), its poses degraded while it lasts.
#include <beaconloc.h>

#include <atomic>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "beaconloc/core/beacon_map_sources.hpp"
#include "beaconloc/dds/diagnostics_publisher.hpp"
#include "beaconloc/dds/first_sample_watch.hpp"
#include "beaconloc/dds/participant.hpp"
#include "localizer_core.hpp"
#include "serving_conflicts.hpp"
#include "shard_membership.hpp"

namespace beaconloc {

struct LocalizerParticipantOptions {
  // Where the site's beacon calibration is kept (calibration_store.hpp), so that it survives a
  // restart of every participant: read at start (none there yet is no error; a file that cannot
  // be read or fails its checks stops the start with the reason), written again whenever the
  // calibration changes. Empty: the calibration lives on the bus alone.
  std::string calibration_file;
  // Selective activation (seed 004 Sec. 3): send each robot's gateway a FiringPlan, the beacons
  // that may reach the robot (LocalizerCore::firing_plan), every kFiringPlanPeriodNs of data time
  // while the robot has a pose. Off: the gateways fire every beacon.
  bool selective_activation = false;
  // A shard of a fleet's localizers (issue 19): it announces itself on localizer_shard and
  // serves only the robots that ShardAssignment gives it among the live shards of its
  // estimator, taking over the robots of a shard that dies or hangs (liveliness, 0.5 s) and
  // handing robots to a shard that joins. Off: it serves every robot (or --robot's one).
  bool shard = false;
};

// A calibration file that exists and cannot be used: the start is refused, with the reason.
class CalibrationFileError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

class LocalizerParticipant {
 public:
  // Throws CalibrationFileError (see LocalizerParticipantOptions::calibration_file).
  LocalizerParticipant(const dds::DdsOptions& dds, LocalizerCore core, LocalizerParticipantOptions options = {});
  void publish_diagnostics() { diagnostics_->publish_now(); }
  // Samples taken from the bus, for a throttle in the same process.
  std::uint64_t odometry_processed() const { return odometry_processed_.load(); }
  std::uint64_t ranges_processed() const { return ranges_processed_.load(); }
  // Poses written (one per odometry sample once localized, plus corrections), and the stamp of
  // the newest odometry sample taken: for benchmarks in the same process.
  std::uint64_t poses_written() const { return poses_written_.load(); }
  // Whether a beacon map has reached it: a throttle in the same process holds the data back
  // until then, so that no good range is refused as no_beacon_map for arriving first.
  bool has_beacon_map() {
    std::lock_guard<std::mutex> lock(mutex_);
    return core_.has_beacon_map();
  }
  StampNs newest_odometry_stamp_ns() const { return newest_odometry_stamp_ns_.load(); }
  // Shards: the live shards it counts (itself among them; 0 when not a shard), and the robots it
  // serves now. For benchmarks in the same process.
  std::size_t live_shards() {
    std::lock_guard<std::mutex> lock(mutex_);
    return shard_ ? shard_->live_shards() : 0;
  }
  std::size_t robots_served() {
    std::lock_guard<std::mutex> lock(mutex_);
    return core_.robot_count();
  }
  std::uint64_t lost_increments() {
    std::lock_guard<std::mutex> lock(mutex_);
    return lost_increments_;
  }

 private:
  msg::Diagnostics diagnostics_snapshot();
  void on_odometry(const msg::Odometry& odometry);
  void fuse_odometry(const msg::Odometry& odometry);  // a robot it serves, under mutex_
  void publish(const LocalizerOutput& out);  // under mutex_
  void publish_firing_plan(const std::string& robot_id, StampNs stamp_ns);  // under mutex_
  void on_peer_diagnostics(const msg::Diagnostics& d, const std::string& writer);
  // Shards: whether this localizer serves the robot now (always, unless a shard); a sample of a
  // robot another shard serves is counted and dropped. Under mutex_.
  bool serves(const std::string& robot_id);
  // Shards: its writer and membership, before any sample (announce_shard); then, once every
  // reader is up, listens to the others, settles, and announces itself (listen_to_shards).
  void announce_shard();
  void listen_to_shards();
  // On its own thread, lease / 5: once settled, announces (the first time) and asserts the
  // liveliness; after a stall past the lease releases every robot (check_shard_stall, under mutex_).
  void keep_shard_alive();
  bool check_shard_stall(StampNs now_ns);  // whether it found a stall (robots released); under mutex_
  bool refuse_announcement(const std::string& reason);  // counted; false (no change). Under mutex_.
  // A robot another shard serves now, or one this shard held through a stall: its estimator and
  // bookkeeping go. Under mutex_.
  void release_robot(const std::string& robot_id);
  void release_robots_not_served();  // after the live shards changed; under mutex_
  // The site's calibration, when it changed (a robot calibrated a group, another localizer's
  // arrived): on the bus, and into the calibration file. Under mutex_.
  void share_calibration();
  // Subscribes to the topic the robots' beacon measurements come on (beacon_range, or raw_tof),
  // with its deadline and liveliness events; fuse gives a sample to the core under mutex_.
  template <class PubSubType, class Fuse>
  void subscribe_beacon_measurements(const dds::TopicSpec& topic, Fuse fuse);

  std::mutex mutex_;
  LocalizerCore core_;
  ServingConflicts conflicts_;
  BeaconMapSources map_sources_;  // the live map writers' maps
  std::string own_diagnostics_writer_;      // its own reports come back to its reader: not a peer
  std::uint64_t peer_reports_refused_ = 0;  // listing more than DIAGNOSTICS_MAX_ROBOTS robots
  std::size_t robots_told_ = 0;             // robots the conflicts know it serves (robots are never removed)
  std::atomic<std::uint64_t> deadline_misses_{0};
  std::atomic<std::uint64_t> odometry_writers_lost_{0};
  std::map<std::string, std::uint64_t> odometry_sequence_;  // newest sequence number per robot
  // 10 s of odometry back or ahead: a new numbering (a restarted or another writer), not losses.
  static constexpr std::uint64_t kSequenceRestart = 1000;
  std::uint64_t lost_increments_ = 0;    // sequence numbers never received
  std::uint64_t sequence_restarts_ = 0;  // jumps beyond kSequenceRestart
  std::atomic<bool> odometry_writer_lost_{false};           // lost, none alive since
  std::atomic<std::uint64_t> range_writers_lost_{0};        // the beacon_range (or raw_tof) writer
  std::atomic<bool> range_writer_lost_{false};              // lost, none alive since
  std::atomic<std::uint64_t> odometry_processed_{0};
  std::atomic<std::uint64_t> ranges_processed_{0};
  std::atomic<std::uint64_t> poses_written_{0};
  std::atomic<StampNs> newest_odometry_stamp_ns_{0};
  LocalizerParticipantOptions options_;
  std::string map_frame_id_ = "map";               // the beacon map's, for the calibration's positions
  std::uint64_t calibration_shared_revision_ = 0;  // core_.calibration_revision() last shared
  std::string own_calibration_writer_;             // its own calibration comes back to its reader
  std::uint64_t calibration_saves_failed_ = 0;
  std::uint64_t calibrations_refused_too_large_ = 0;  // more groups or beacons than kMaxBeacons
  std::uint64_t calibrations_refused_other_frame_ = 0;  // frame_id not the beacon map's
  std::string calibration_save_error_;             // the last failure, while the newest is unsaved
  std::map<std::string, StampNs> plan_sent_ns_;    // stamp of the pose each robot's last plan came from
  std::uint64_t plans_sent_ = 0;
  std::optional<ShardMembership> shard_;      // with options_.shard
  std::uint64_t other_shard_samples_ = 0;     // samples of robots it does not serve (serves())
  std::uint64_t robots_handed_over_ = 0;      // robots released (to another shard, or after a stall)
  std::uint64_t shard_stalls_ = 0;            // stalls past its lease
  std::map<std::string, std::uint64_t> shard_announcements_refused_;  // by reason
  StampNs shard_lease_ns_ = 0;                // its announcement writer's (topics.xml)
  bool shard_announced_ = false;
  std::optional<StampNs> shard_asserted_ns_;  // the newest assertion; none while settling
  // Readers matched by the announcement writer since last asked: it announces again.
  class MatchListener : public eprosima::fastdds::dds::DataWriterListener {
   public:
    void on_publication_matched(eprosima::fastdds::dds::DataWriter*,
                                const eprosima::fastdds::dds::PublicationMatchedStatus& s) override {
      if (s.current_count_change > 0) matched_ = true;
    }
    bool matched_since_asked() { return matched_.exchange(false); }

   private:
    std::atomic<bool> matched_{false};
  };
  MatchListener shard_matches_;  // outlives shard_writer_
  // The entities, owned, declared last and so gone first (the shard's liveliness task, then the
  // readers, then the writers), before what they use goes.
  dds::Participant participant_;
  dds::Writer pose_writer_;
  dds::Writer state_writer_;  // EstimatorState: what the estimator holds beside the pose
  dds::Writer calibration_writer_;  // BeaconCalibration: the site's calibrated beacon groups
  dds::Writer plan_writer_;         // FiringPlan, with selective activation
  dds::Writer shard_writer_;        // LocalizerShard, with options_.shard
  // Before diagnostics_, which reports its count: it goes after the Diagnostics task stops.
  std::unique_ptr<dds::FirstSampleWatch> map_reader_;  // recreated when mute (first_sample_watch.hpp)
  std::unique_ptr<dds::DiagnosticsPublisher> diagnostics_;
  std::vector<dds::Reader> readers_;
  std::unique_ptr<dds::PeriodicTask> shard_liveliness_;  // asserts shard_writer_'s; stops first
};

}  // namespace beaconloc
