#pragma once
// Records the PoseEstimate topic with the wall time each pose arrived: the demo and the tests
// measure accuracy against ground truth and the pose rate with it.
#include <chrono>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "beaconloc/core/estimator.hpp"
#include "beaconloc/dds/participant.hpp"

namespace beaconloc {

struct RecordedPose {
  std::string robot_id;
  PoseEstimate estimate;
  std::string estimator;
  std::chrono::steady_clock::time_point received;
};

class PoseRecorder {
 public:
  explicit PoseRecorder(const dds::DdsOptions& dds);
  ~PoseRecorder();
  std::vector<RecordedPose> poses() const;

 private:
  mutable std::mutex mutex_;
  std::vector<RecordedPose> poses_;
  dds::Participant participant_;
};

// Writes poses as CSV: robot_id,stamp_ns,x_m,y_m,yaw_rad,cov_xx,cov_yy,cov_yawyaw,status.
void write_poses_csv(const std::string& path, const std::vector<RecordedPose>& poses);

}  // namespace beaconloc

#include "beaconloc/core/pose_error.hpp"
#include "beaconloc/core/truth_track.hpp"

namespace beaconloc {

// Reads a truth CSV written by the gateway (stamp_ns,x_m,y_m,yaw_rad). Throws naming the file
// and line of a malformed row.
TruthTrack load_truth_csv(const std::string& path);

struct PoseRunSummary {
  std::size_t poses = 0;
  double pose_rate_hz = 0.0;   // poses / arrival time span
  PoseErrorAccumulator error;  // over poses whose stamp the truth covers
  std::size_t poses_without_truth = 0;
};
PoseRunSummary summarize(const std::vector<RecordedPose>& poses, const TruthTrack& truth);

}  // namespace beaconloc
