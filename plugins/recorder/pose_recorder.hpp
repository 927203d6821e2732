#pragma once
// Records the PoseEstimate topic with the wall time each pose arrived: the demo, `run`,
// `monitor` and the tests measure accuracy against ground truth and the pose rate with it.
// A pose at the stamp of the previous one of its robot and writer is that pose corrected by a
// range (the localizer publishes a correction at once): it replaces the previous one, so each
// stamp is scored once.
// A pose with a non-finite number is refused and counted (PoseTally), never recorded.
// Every pose is kept for scoring, or (a monitor that neither scores nor writes) only the newest
// of each robot: memory O(robots) however long it runs.
#include <chrono>
#include <map>
#include <mutex>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "beaconloc/dds/participant.hpp"
#include "evaluation.hpp"
#include "pose_tally.hpp"

namespace beaconloc {

class PoseRecorder {
 public:
  enum class Keep { kEveryPose, kNewestPerRobot };
  explicit PoseRecorder(const dds::DdsOptions& dds, Keep keep = Keep::kEveryPose);
  // Every pose received (kEveryPose), or the newest of each robot (kNewestPerRobot).
  std::vector<RecordedPose> poses() const;
  std::size_t count() const;        // finite poses received, corrections not counted again
  std::size_t stored() const;       // poses held: count() with kEveryPose, one per robot otherwise
  StampNs newest_stamp_ns() const;  // of the newest pose received, 0 before the first
  std::optional<RecordedPose> newest() const;
  std::map<std::string, RobotPoses> robots() const;  // O(robots) copy

 private:
  const Keep keep_;
  mutable std::mutex mutex_;
  PoseTally tally_;
  std::vector<RecordedPose> poses_;                                              // kEveryPose
  std::map<std::pair<std::string, std::string>, std::size_t> newest_of_writer_;  // (robot, writer) -> poses_
  dds::Participant participant_;
  dds::Reader reader_;  // last: stops before what its callback uses goes
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
