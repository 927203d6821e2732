#include "pose_recorder.hpp"

#include <beaconlocPubSubTypes.h>

#include "beaconloc/dds/convert.hpp"

namespace beaconloc {

PoseRecorder::PoseRecorder(const dds::DdsOptions& dds) : participant_(dds, "beaconloc.pose_recorder") {
  participant_.subscribe<msg::PoseEstimatePubSubType>(
      dds::kPoseEstimateTopic, [this](const msg::PoseEstimate& m) {
        RecordedPose p{{m.robot_id(), dds::from_msg(m), m.estimator()}, std::chrono::steady_clock::now()};
        std::lock_guard<std::mutex> lock(mutex_);
        auto [newest, first] = newest_of_robot_.try_emplace(p.row.robot_id, poses_.size());
        if (!first && poses_[newest->second].row.estimate.stamp_ns == p.row.estimate.stamp_ns) {
          poses_[newest->second] = std::move(p);  // a correction of the same pose
          return;
        }
        newest->second = poses_.size();
        poses_.push_back(std::move(p));
      });
}

PoseRecorder::~PoseRecorder() { participant_.close(); }

std::vector<RecordedPose> PoseRecorder::poses() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return poses_;
}

std::size_t PoseRecorder::count() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return poses_.size();
}

StampNs PoseRecorder::newest_stamp_ns() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return poses_.empty() ? 0 : poses_.back().row.estimate.stamp_ns;
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
