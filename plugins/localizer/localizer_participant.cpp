#include "localizer_participant.hpp"

#include <beaconlocPubSubTypes.h>

#include <fastdds/dds/subscriber/SampleInfo.hpp>

#include "beaconloc/dds/convert.hpp"
#include "beaconloc/dds/wall_clock.hpp"

namespace beaconloc {

using eprosima::fastdds::dds::DataReader;
using eprosima::fastdds::dds::SampleInfo;

class LocalizerParticipant::Listener : public eprosima::fastdds::dds::DataReaderListener {
 public:
  explicit Listener(LocalizerParticipant& owner) : owner_(owner) {}
  void on_data_available(DataReader* reader) override {
    const std::string& topic = reader->get_topicdescription()->get_name();
    if (topic == dds::kOdometryTopic.name) {
      owner_.on_odometry(reader);
    } else if (topic == dds::kBeaconRangeTopic.name) {
      owner_.on_range(reader);
    } else {
      owner_.on_beacon_map(reader);
    }
  }
  void on_requested_deadline_missed(DataReader*,
                                    const eprosima::fastdds::dds::RequestedDeadlineMissedStatus&) override {
    ++owner_.deadline_misses_;
  }

 private:
  LocalizerParticipant& owner_;
};

LocalizerParticipant::LocalizerParticipant(const dds::DdsOptions& dds, LocalizerCore core)
    : core_(std::move(core)),
      listener_(std::make_unique<Listener>(*this)),
      participant_(dds, "beaconloc.localizer." + core_.estimator_name()),
      pose_writer_(participant_.writer<msg::PoseEstimatePubSubType>(dds::kPoseEstimateTopic)),
      diagnostics_writer_(participant_.writer<msg::DiagnosticsPubSubType>(dds::kDiagnosticsTopic)),
      map_reader_(participant_.reader<msg::BeaconMapPubSubType>(dds::kBeaconMapTopic, listener_.get())),
      odometry_reader_(participant_.reader<msg::OdometryPubSubType>(dds::kOdometryTopic, listener_.get())),
      range_reader_(participant_.reader<msg::BeaconRangePubSubType>(dds::kBeaconRangeTopic, listener_.get())),
      diagnostics_task_(std::make_unique<dds::PeriodicTask>(std::chrono::seconds(1),
                                                            [this] { publish_diagnostics(); })) {}

LocalizerParticipant::~LocalizerParticipant() {
  diagnostics_task_.reset();
  publish_diagnostics();
  participant_.close();
}

void LocalizerParticipant::on_beacon_map(DataReader* reader) {
  msg::BeaconMap m;
  SampleInfo info;
  while (reader->take_next_sample(&m, &info) == ReturnCode_t::RETCODE_OK) {
    if (!info.valid_data) continue;
    std::lock_guard<std::mutex> lock(mutex_);
    core_.set_beacon_map(dds::from_msg(m));
  }
}

void LocalizerParticipant::on_range(DataReader* reader) {
  msg::BeaconRange m;
  SampleInfo info;
  while (reader->take_next_sample(&m, &info) == ReturnCode_t::RETCODE_OK) {
    if (!info.valid_data) continue;
    std::lock_guard<std::mutex> lock(mutex_);
    core_.on_range(m.robot_id(), dds::from_msg(m));
  }
}

void LocalizerParticipant::on_odometry(DataReader* reader) {
  msg::Odometry m;
  SampleInfo info;
  while (reader->take_next_sample(&m, &info) == ReturnCode_t::RETCODE_OK) {
    if (!info.valid_data) continue;
    std::optional<LocalizerOutput> out;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      out = core_.on_odometry(m.robot_id(), dds::from_msg(m));
    }
    if (!out) continue;
    msg::PoseEstimate p;
    p.robot_id(out->robot_id);
    p.stamp_ns(out->estimate.stamp_ns);
    p.x_m(out->estimate.pose_map_base.x());
    p.y_m(out->estimate.pose_map_base.y());
    p.yaw_rad(out->estimate.pose_map_base.z());
    std::array<double, 9> cov{};
    Eigen::Map<Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(cov.data()) = out->estimate.covariance;
    p.covariance(cov);
    p.estimator(core_.estimator_name());
    p.status(dds::to_msg(out->estimate.status));
    p.beacons_used(out->beacons_used);
    pose_writer_->write(&p);
  }
}

void LocalizerParticipant::publish_diagnostics() {
  msg::Diagnostics d;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    const PoseStatus worst = core_.worst_status();
    msg::ParticipantStatus status = msg::PARTICIPANT_STATUS_OK;
    std::string message = std::to_string(core_.robot_count()) + " robot(s), worst pose status " +
                          to_string(worst);
    if (!core_.has_beacon_map()) {
      status = msg::PARTICIPANT_STATUS_DEGRADED;
      message = "waiting for the beacon map";
    } else if (worst == PoseStatus::kDegraded || worst == PoseStatus::kLost) {
      status = msg::PARTICIPANT_STATUS_DEGRADED;
    }
    d = dds::make_diagnostics(participant_.name(), dds::wall_clock_ns(), core_.counts(),
                              deadline_misses_.load(), status, message);
  }
  diagnostics_writer_->write(&d);
}

}  // namespace beaconloc
