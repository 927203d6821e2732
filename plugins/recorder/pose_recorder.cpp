#include "pose_recorder.hpp"

#include <beaconlocPubSubTypes.h>

#include "beaconloc/dds/convert.hpp"

namespace beaconloc {

PoseRecorder::PoseRecorder(const dds::DdsOptions& dds, Keep keep)
    : keep_(keep), participant_(dds, "beaconloc.pose_recorder") {
  reader_ = participant_.subscribe_with_info<msg::PoseEstimatePubSubType>(
      dds::kPoseEstimateTopic,
      [this](const msg::PoseEstimate& m, const eprosima::fastdds::dds::SampleInfo& info) {
        const std::string writer = dds::writer_id(info.publication_handle);
        RecordedPose p{{m.robot_id(), dds::from_msg(m), m.estimator()}, std::chrono::steady_clock::now(), writer};
        std::lock_guard<std::mutex> lock(mutex_);
        const PoseTally::Added added = tally_.add(p);
        if (keep_ != Keep::kEveryPose || added == PoseTally::Added::kNonFinite) return;
        auto [newest, first] = newest_of_writer_.try_emplace({p.row.robot_id, writer}, poses_.size());
        if (!first && added == PoseTally::Added::kCorrection) {
          poses_[newest->second] = std::move(p);
          return;
        }
        newest->second = poses_.size();
        poses_.push_back(std::move(p));
      });
}

std::vector<RecordedPose> PoseRecorder::poses() const {
  std::lock_guard<std::mutex> lock(mutex_);
  if (keep_ == Keep::kEveryPose) return poses_;
  std::vector<RecordedPose> newest;
  for (const auto& [id, r] : tally_.robots()) {
    if (r.newest) newest.push_back(*r.newest);
  }
  return newest;
}

std::size_t PoseRecorder::count() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return tally_.poses();
}

std::size_t PoseRecorder::stored() const {
  std::lock_guard<std::mutex> lock(mutex_);
  if (keep_ == Keep::kEveryPose) return poses_.size();
  std::size_t n = 0;
  for (const auto& [id, r] : tally_.robots()) n += r.newest ? 1 : 0;
  return n;
}

StampNs PoseRecorder::newest_stamp_ns() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return tally_.newest() ? tally_.newest()->row.estimate.stamp_ns : 0;
}

std::optional<RecordedPose> PoseRecorder::newest() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return tally_.newest();
}

std::map<std::string, RobotPoses> PoseRecorder::robots() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return tally_.robots();
}

std::vector<EstimateRow> rows_of(const std::vector<RecordedPose>& poses) {
  std::vector<EstimateRow> rows;
  rows.reserve(poses.size());
  for (const auto& p : poses) rows.push_back(p.row);
  return rows;
}

PoseRunSummary summarize(const std::vector<RecordedPose>& poses, const TruthTrack& truth,
                         const EvaluationOptions& options) {
  PoseRunSummary s;
  s.poses = poses.size();
  if (poses.size() >= 2) {
    const double span_s =
        std::chrono::duration<double>(poses.back().received - poses.front().received).count();
    if (span_s > 0.0) s.pose_rate_hz = static_cast<double>(poses.size() - 1) / span_s;
  }
  s.metrics = evaluate(truth, rows_of(poses), options);
  return s;
}

}  // namespace beaconloc
