#pragma once
// Records the PoseEstimate topic with the wall time each pose arrived: the demo, `run`,
// `monitor` and the tests measure accuracy against ground truth and the pose rate with it.
// A pose at the stamp of a robot's previous one is that pose corrected by a range (the localizer
// publishes a correction at once): it replaces the previous one, so each stamp is scored once.
#include <chrono>
#include <map>
#include <mutex>
#include <string>
#include <vector>

#include "beaconloc/dds/participant.hpp"
#include "evaluation.hpp"

namespace beaconloc {

struct RecordedPose {
  EstimateRow row;
  std::chrono::steady_clock::time_point received;
};

class PoseRecorder {
 public:
  explicit PoseRecorder(const dds::DdsOptions& dds);
  ~PoseRecorder();
  std::vector<RecordedPose> poses() const;
  std::size_t count() const;
  StampNs newest_stamp_ns() const;  // 0 before the first pose

 private:
  mutable std::mutex mutex_;
  std::vector<RecordedPose> poses_;
  std::map<std::string, std::size_t> newest_of_robot_;  // index into poses_
  dds::Participant participant_;
};

std::vector<EstimateRow> rows_of(const std::vector<RecordedPose>& poses);

struct PoseRunSummary {
  std::size_t poses = 0;
  double pose_rate_hz = 0.0;  // poses / arrival time span
  Metrics metrics;
};
PoseRunSummary summarize(const std::vector<RecordedPose>& poses, const TruthTrack& truth,
                         const EvaluationOptions& options = {});

}  // namespace beaconloc
