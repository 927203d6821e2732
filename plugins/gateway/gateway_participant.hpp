#pragma once
// beacon-gateway participant: publishes the source's BeaconMap (transient local), then its
// RawTof, Odometry and LaserScan samples, paced against the wall clock (x speed) or as fast as a
// throttle lets it; writes the source's ground truth to a CSV when asked. A source that calls its
// beacons (the simulator) fires by the FiringPlan a localizer sends for its robot while the plan
// is fresh, and every beacon otherwise (seed 004 selective activation).
#include <beaconloc.h>

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <fstream>
#include <functional>
#include <iterator>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>

#include "beaconloc/core/rejection_counter.hpp"
#include "beaconloc/dds/diagnostics_publisher.hpp"
#include "beaconloc/dds/participant.hpp"
#include "beaconloc/dds/periodic_task.hpp"
#include "beaconloc/dds/wall_clock.hpp"
#include "firing_scheduler.hpp"
#include "replay/bus_recording.hpp"
#include "source.hpp"

namespace beaconloc {

struct GatewayOptions {
  std::string robot_id = "robot1";
  double duration_s = 0.0;  // seconds of source time to run; 0 = the whole source / until stopped
  double speed = 1.0;       // source seconds per wall second; 0 = as fast as the throttle allows
  // Paced speeds from 1000x slower than real time (a day of wall time for 86 s of data) to 10^4x
  // faster (beyond, the pipeline cannot keep up and pacing means nothing): --speed is refused
  // outside them, so that the wall-clock offset of any stamp is a finite, representable time.
  static constexpr double kMinSpeed = 1e-3;
  static constexpr double kMaxSpeed = 1e4;
  std::uint64_t seed = 1;
  std::string truth_csv;  // ground truth written here when not empty
  // The samples written, when not empty: a recording of the bus (replay/bus_recording.hpp: tof.csv
  // or pulse.csv, odometry.csv, scan.csv, receivers.csv), with the simulator's hidden truth (who
  // fired, echo or not); `beaconloc run --replay` replays it.
  std::string record_dir;
  std::string frame_id = "map";
  // Every firing of the source (fire_stamp_ns,beacon_id,planned,heard), as CSV, when not empty:
  // which slots followed a localizer's firing plan (seed 004 selective activation).
  std::string firings_csv;
  // Simulated stamps start at 0; live, they are offset to the wall clock at start. A replayed
  // recording keeps its own clock either way. false: byte-identical runs (run).
  bool wall_clock_stamps = true;
  // Before the first sample, wait (until stopped) for this many matched readers on each
  // measurement topic (TOFs or pulse arrivals, and odometry) besides the run's own: a recorder or a
  // second localizer hears the run from its start. 0: no wait.
  int wait_for_readers = 0;
  // The run's own readers of each (`run` sets them: its decoder or localizer, its localizer and bridge).
  int own_beacon_readers = 0;
  int own_odometry_readers = 0;
  static constexpr int kMaxWaitForReaders = 1000;
};

// What the gateway has written so far (read by a throttle in the same process).
struct GatewayProgress {
  std::atomic<std::uint64_t> odometry_written{0};
  std::atomic<std::uint64_t> tofs_written{0};  // beacon measurements: RawTof or PulseArrival samples
  std::atomic<StampNs> newest_stamp_ns{0};
};

class GatewayParticipant {
 public:
  // Truth of the source at a stamp (the stamp the published samples carry).
  using TruthCallback = std::function<void(StampNs stamp_ns, const Pose2& truth_map_base, bool has_yaw)>;
  // Called once the beacon map is written, before the first sample, and after each step's
  // samples are written; may block to hold the gateway back.
  using Throttle = std::function<void()>;

  GatewayParticipant(const dds::DdsOptions& dds, GatewayOptions options, std::unique_ptr<Source> source,
                     TruthCallback on_truth = {}, Throttle throttle = {});
  ~GatewayParticipant();
  // Waits until the odometry writer and the writer of the source's beacon measurements (TOFs or
  // pulse arrivals) each have a matched reader (false on timeout), so that a run in one process
  // loses none of its first samples.
  bool wait_for_readers(std::chrono::milliseconds timeout) const;
  // How the source hears its beacons (Source::beacon_input): RawTof or PulseArrival samples.
  BeaconInput beacon_input() const { return source_->beacon_input(); }
  void start();
  void stop();
  void publish_diagnostics() { diagnostics_->publish_now(); }
  bool finished() const { return finished_.load(); }
  const GatewayProgress& progress() const { return progress_; }
  // Source time covered so far, and in all, for progress lines.
  double elapsed_s() const { return elapsed_s_.load(); }
  double total_s() const { return total_s_; }
  // Throws if the run loop failed (e.g. the truth file could not be written).
  void rethrow_failure() const;

 private:
  void run();
  // options_.wait_for_readers on each measurement writer; false when stopped first.
  bool wait_for_readers_before_start();
  void publish(SourceEvent& e, StampNs offset_ns);
  // The run thread's write to the recording (record_), if any; a failure ends the recording and
  // is the run's failure.
  template <class Write>
  void record(Write&& write);
  // The source fires by the newest fresh firing plan, or every beacon (FiringScheduler); the
  // firings go to the firing log.
  void apply_firing_plan(StampNs now_stamp_ns);
  void log_firings(StampNs offset_ns);
  std::string firing_summary();
  void count(bool written);
  // On the liveliness task: the map again each second for kMapRepeats s after the newest reader matched.
  void repeat_map_after_match();
  static constexpr std::size_t kMapRepeats = 10;

  GatewayOptions options_;
  std::unique_ptr<Source> source_;
  TruthCallback on_truth_;
  Throttle throttle_;
  dds::Participant participant_;
  // The beacon map is written once (transient local), and again each second for kMapRepeats s after
  // each reader that matched: a late-joining reader of a transient-local writer misses its samples
  // now and then (eProsima/Fast-DDS#3822, open), and more often secured, where it drops what
  // arrives before it holds the writer's keys: the decoder or the localizer stayed "waiting for
  // the beacon map" in 4 of 24 secured starts on a loaded machine. Readers take an unchanged map as
  // nothing new.
  class MapReaders : public eprosima::fastdds::dds::DataWriterListener {
   public:
    void on_publication_matched(eprosima::fastdds::dds::DataWriter*,
                                const eprosima::fastdds::dds::PublicationMatchedStatus& s) override {
      if (s.current_count_change > 0) newest_match_ns = dds::steady_clock_ns();
    }
    std::atomic<StampNs> newest_match_ns{0};
  };
  MapReaders map_readers_;  // before the writer it listens to
  // Owned; what writes through them (the run thread, the liveliness and Diagnostics tasks) is
  // declared after them, so stops before they go.
  dds::Writer map_writer_;
  dds::Writer tof_writer_;
  dds::Writer pulse_writer_;
  dds::Writer odometry_writer_;
  dds::Writer scan_writer_;
  std::ofstream truth_;
  std::optional<BusRecordingWriter> record_;  // the samples as published, when options_.record_dir is set
  std::ofstream firings_;
  // Selective activation: the plans for this robot (a source that honours them), judged by the
  // gateway's stamps; -1 until the run has started.
  std::mutex plan_mutex_;
  std::optional<FiringScheduler> scheduler_;
  std::uint64_t plans_ignored_ = 0;  // plans for its robot to a source that fires what it fired
  std::uint64_t firings_planned_ = 0;  // the source's firings by a plan
  std::uint64_t firings_every_ = 0;    // and of every beacon in turn
  std::atomic<StampNs> now_stamp_ns_{-1};
  msg::BeaconMap map_msg_;  // set by run() before map_written_, not changed after
  std::atomic<bool> map_written_{false};
  StampNs map_repeat_match_ns_ = 0;  // the liveliness task's: the match its repeats are for,
  std::size_t map_repeats_ = 0;      // and how many it has written
  std::uint64_t odometry_sequence_ = 0;
  std::mutex counts_mutex_;
  RejectionCounter counts_;  // accepted = samples written; rejected = write failures
  std::unique_ptr<dds::DiagnosticsPublisher> diagnostics_;
  std::unique_ptr<dds::PeriodicTask> liveliness_;  // asserts the TOF and odometry writers' liveliness
  dds::Reader plan_reader_;  // FiringPlan: after what it uses (the scheduler), so it stops first
  GatewayProgress progress_;
  std::atomic<double> elapsed_s_{0.0};
  double total_s_ = 0.0;
  std::atomic<bool> stop_{false};
  // stop() wakes the pacing wait at once, however long it was to sleep.
  std::mutex stop_mutex_;
  std::condition_variable stop_cv_;
  std::atomic<bool> finished_{false};
  std::string failure_;
  std::thread thread_;
};

}  // namespace beaconloc
