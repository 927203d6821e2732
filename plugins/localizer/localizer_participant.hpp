#pragma once
// localizer participant: Odometry + BeaconRange (+ BeaconMap) -> PoseEstimate, through the
// LocalizerCore (one estimator plugin instance per robot); Diagnostics at 1 Hz.
#include <atomic>
#include <memory>
#include <mutex>

#include "beaconloc/dds/participant.hpp"
#include "beaconloc/dds/periodic_task.hpp"
#include "localizer_core.hpp"

namespace beaconloc {

class LocalizerParticipant {
 public:
  LocalizerParticipant(const dds::DdsOptions& dds, LocalizerCore core);
  ~LocalizerParticipant();
  void publish_diagnostics();

 private:
  class Listener;
  void on_odometry(eprosima::fastdds::dds::DataReader* reader);
  void on_range(eprosima::fastdds::dds::DataReader* reader);
  void on_beacon_map(eprosima::fastdds::dds::DataReader* reader);

  std::mutex mutex_;
  LocalizerCore core_;
  std::atomic<std::uint64_t> deadline_misses_{0};
  std::unique_ptr<Listener> listener_;
  dds::Participant participant_;
  eprosima::fastdds::dds::DataWriter* pose_writer_;
  eprosima::fastdds::dds::DataWriter* diagnostics_writer_;
  eprosima::fastdds::dds::DataReader* map_reader_;
  eprosima::fastdds::dds::DataReader* odometry_reader_;
  eprosima::fastdds::dds::DataReader* range_reader_;
  std::unique_ptr<dds::PeriodicTask> diagnostics_task_;
};

}  // namespace beaconloc
