#pragma once
// beacon-gateway participant: publishes the BeaconMap (transient local), RawTof and Odometry
// from a source. Source here: the simulator, paced against the wall clock (x speed).
#include <atomic>
#include <cstdint>
#include <fstream>
#include <functional>
#include <memory>
#include <mutex>
#include <string>
#include <thread>

#include "beaconloc/core/rejection_counter.hpp"
#include "beaconloc/dds/diagnostics_publisher.hpp"
#include "beaconloc/dds/participant.hpp"
#include "sim/scenario.hpp"

namespace beaconloc {

struct GatewayOptions {
  std::string robot_id = "robot1";
  double duration_s = 0.0;  // simulated seconds to run; 0 = until stopped
  double speed = 1.0;       // simulated seconds per wall second
  std::uint64_t seed = 1;
  std::string truth_csv;  // ground truth written here when not empty
  std::string frame_id = "map";
};

class GatewayParticipant {
 public:
  // Truth of every odometry stamp, for evaluation in the same process.
  using TruthCallback = std::function<void(StampNs stamp_ns, const Pose2& truth_map_base)>;

  GatewayParticipant(const dds::DdsOptions& dds, GatewayOptions options, sim::Scenario scenario,
                     TruthCallback on_truth = {});
  ~GatewayParticipant();
  void start();
  void stop();
  bool finished() const { return finished_.load(); }
  // Throws if the run loop failed (e.g. the truth file could not be written).
  void rethrow_failure() const;

 private:
  void run();
  void count(bool written);

  GatewayOptions options_;
  sim::Scenario scenario_;
  TruthCallback on_truth_;
  dds::Participant participant_;
  eprosima::fastdds::dds::DataWriter* map_writer_;
  eprosima::fastdds::dds::DataWriter* tof_writer_;
  eprosima::fastdds::dds::DataWriter* odometry_writer_;
  std::ofstream truth_;
  std::mutex counts_mutex_;
  RejectionCounter counts_;  // accepted = samples written; rejected = write failures
  std::unique_ptr<dds::DiagnosticsPublisher> diagnostics_;
  std::atomic<bool> stop_{false};
  std::atomic<bool> finished_{false};
  std::string failure_;
  std::thread thread_;
};

}  // namespace beaconloc
