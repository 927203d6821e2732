#include "bus_recorder.hpp"

#include <beaconlocPubSubTypes.h>

#include "beaconloc/core/estimator.hpp"
#include "beaconloc/dds/convert.hpp"
#include "beaconloc/dds/topics.hpp"
#include "evaluation.hpp"

namespace beaconloc {
namespace {

bool same_beacons(const BeaconMap& a, const BeaconMap& b) {
  const auto& x = a.beacons();
  const auto& y = b.beacons();
  const auto& lx = a.local_beacons();
  const auto& ly = b.local_beacons();
  if (x.size() != y.size() || lx.size() != ly.size()) return false;
  for (std::size_t i = 0; i < x.size(); ++i) {
    if (x[i].id != y[i].id || x[i].group != y[i].group || x[i].position_map_m != y[i].position_map_m)
      return false;
  }
  for (std::size_t i = 0; i < lx.size(); ++i) {
    if (lx[i].id != ly[i].id || lx[i].group != ly[i].group ||
        lx[i].position_group_m != ly[i].position_group_m) {
      return false;
    }
  }
  return true;
}

}  // namespace

BusRecorder::BusRecorder(const dds::DdsOptions& dds, BusRecorderOptions options)
    : options_(std::move(options)),
      participant_(dds, "beaconloc.recorder." + options_.robot_id),
      writer_(options_.out_dir, false),
      estimates_(options_.out_dir + "/estimate.csv", estimates_csv_header()) {
  if (options_.receivers) writer_.write_receivers(*options_.receivers);
  const std::string& robot = options_.robot_id;
  tof_reader_ =
      participant_.subscribe<msg::RawTofPubSubType>(dds::kRawTofTopic, [this, robot](const msg::RawTof& m) {
        if (m.robot_id() == robot) record(bus_recording::kTofFile, [&] { writer_.write(dds::from_msg(m)); });
      });
  pulse_reader_ = participant_.subscribe<msg::PulseArrivalPubSubType>(
      dds::kPulseArrivalTopic, [this, robot](const msg::PulseArrival& m) {
        if (m.robot_id() == robot)
          record(bus_recording::kPulseFile, [&] { writer_.write(dds::from_msg(m)); });
      });
  odometry_reader_ = participant_.subscribe<msg::OdometryPubSubType>(
      dds::kOdometryTopic, [this, robot](const msg::Odometry& m) {
        if (m.robot_id() == robot)
          record(bus_recording::kOdometryFile, [&] { writer_.write(dds::from_msg(m)); });
      });
  scan_reader_ = participant_.subscribe<msg::LaserScanPubSubType>(
      dds::kLaserScanTopic, [this, robot](const msg::LaserScan& m) {
        if (m.robot_id() == robot) record(bus_recording::kScanFile, [&] { writer_.write(dds::from_msg(m)); });
      });
  map_reader_ =
      participant_.subscribe<msg::BeaconMapPubSubType>(dds::kBeaconMapTopic, [this](const msg::BeaconMap& m) {
        try {
          on_beacon_map(BeaconMap(dds::from_msg(m)));
        } catch (const std::invalid_argument&) {
          std::lock_guard<std::mutex> lock(mutex_);
          ++refused_["unusable_beacon_map"];
        } catch (const std::runtime_error&) {
          std::lock_guard<std::mutex> lock(mutex_);
          ++refused_["write_failed"];
        }
      });
  pose_reader_ = participant_.subscribe<msg::PoseEstimatePubSubType>(
      dds::kPoseEstimateTopic, [this, robot](const msg::PoseEstimate& m) {
        if (m.robot_id() != robot) return;
        const EstimateRow row{m.robot_id(), dds::from_msg(m), m.estimator()};
        std::lock_guard<std::mutex> lock(mutex_);
        if (!publishable(row.estimate)) {  // the localizers publish none: counted, never written
          ++refused_["non_finite_pose"];
          return;
        }
        try {
          estimates_.write_line(estimates_csv_row(row));
          ++written_["estimate.csv"];
        } catch (const std::runtime_error&) {
          ++refused_["write_failed"];
        }
      });
}

template <class Write>
void BusRecorder::record(const char* file, Write&& write) {
  std::lock_guard<std::mutex> lock(mutex_);
  try {
    write();
  } catch (const std::runtime_error&) {
    ++refused_["write_failed"];  // a full disk, say: the command reports it
    return;
  }
  ++written_[file];
  ++samples_;
}

void BusRecorder::on_beacon_map(const BeaconMap& map) {
  std::lock_guard<std::mutex> lock(mutex_);
  // The gateway writes its map again for readers that join late: an unchanged map is not new.
  if (map_ && same_beacons(*map_, map)) return;
  writer_.write_beacons(map);  // throws on a failed write: counted by the caller
  ++written_[bus_recording::kBeaconsFile];
  map_ = map;
}

std::map<std::string, std::uint64_t> BusRecorder::written() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return written_;
}

std::map<std::string, std::uint64_t> BusRecorder::refused() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return refused_;
}

std::uint64_t BusRecorder::samples_written() const { return samples_.load(); }

}  // namespace beaconloc
