#pragma once
// What a monitor keeps of the pose stream, without DDS: per robot its newest pose, how many came,
// how many were refused as non-finite, and the writers (localizers) they came from. O(robots +
// writers), whatever the number of poses: the pose recorder adds every pose only when asked to.
#include <chrono>
#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "evaluation.hpp"

namespace beaconloc {

struct RecordedPose {
  EstimateRow row;
  std::chrono::steady_clock::time_point received;
  std::string writer;  // dds::writer_id of the writer it came from
};

// Two writers serve one robot at once when their poses alternate: a writer's pose arrives after
// another's, within this of its own previous one (a localizer writes one per odometry sample,
// 100 Hz). A writer replaced by another (a localizer restarted, a shard's robot taken over or
// handed to a new shard) never writes after its successor: no conflict.
inline constexpr std::chrono::milliseconds kConcurrentWritersWithin{1000};

struct PoseWriter {
  std::string estimator;  // of its newest pose
  std::uint64_t poses = 0;
  StampNs newest_stamp_ns = 0;
  std::chrono::steady_clock::time_point last_heard;
};

struct RobotPoses {
  std::optional<RecordedPose> newest;  // finite; none while every pose was refused
  std::uint64_t poses = 0;       // finite poses, a writer's correction at its pose's stamp not counted again
  std::uint64_t non_finite = 0;  // refused: not publishable() (a non-finite number, a broken covariance)
  std::map<std::string, PoseWriter> writers;  // by writer id (one per localizer)
  bool had_conflict = false;                  // two writers at once, ever
  std::optional<std::chrono::steady_clock::time_point> last_alternation;  // of the newest conflict
  // The writers serving the robot at `now`: the newest pose's, and while their poses alternated
  // within kConcurrentWritersWithin, every writer heard within it (more than one: a conflict).
  std::vector<const PoseWriter*> current_writers(std::chrono::steady_clock::time_point now) const;
};

class PoseTally {
 public:
  enum class Added {
    kNew,         // a pose at a new stamp
    kCorrection,  // at the stamp of its writer's newest pose of the robot: it replaces that one
    kNonFinite,   // refused, counted
  };
  Added add(const RecordedPose& pose);
  const std::map<std::string, RobotPoses>& robots() const { return robots_; }
  std::uint64_t poses() const { return poses_; }                         // over every robot
  const std::optional<RecordedPose>& newest() const { return newest_; }  // of any robot

 private:
  std::map<std::string, RobotPoses> robots_;
  std::uint64_t poses_ = 0;
  std::optional<RecordedPose> newest_;
};

}  // namespace beaconloc
