#include "pose_recorder.hpp"

#include <beaconlocPubSubTypes.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <iomanip>
#include <stdexcept>

#include "beaconloc/dds/convert.hpp"

namespace beaconloc {

PoseRecorder::PoseRecorder(const dds::DdsOptions& dds) : participant_(dds, "beaconloc.pose_recorder") {
  participant_.subscribe<msg::PoseEstimatePubSubType>(
      dds::kPoseEstimateTopic, [this](const msg::PoseEstimate& m) {
        RecordedPose p{m.robot_id(), dds::from_msg(m), m.estimator(), std::chrono::steady_clock::now()};
        std::lock_guard<std::mutex> lock(mutex_);
        poses_.push_back(std::move(p));
      });
}

PoseRecorder::~PoseRecorder() { participant_.close(); }

std::vector<RecordedPose> PoseRecorder::poses() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return poses_;
}

void write_poses_csv(const std::string& path, const std::vector<RecordedPose>& poses) {
  std::ofstream out(path);
  if (!out) throw std::runtime_error("cannot write '" + path + "'");
  out << "robot_id,stamp_ns,x_m,y_m,yaw_rad,cov_xx,cov_yy,cov_yawyaw,status\n" << std::setprecision(10);
  for (const auto& p : poses) {
    const auto& e = p.estimate;
    out << p.robot_id << ',' << e.stamp_ns << ',' << e.pose_map_base.x() << ',' << e.pose_map_base.y() << ','
        << e.pose_map_base.z() << ',' << e.covariance(0, 0) << ',' << e.covariance(1, 1) << ','
        << e.covariance(2, 2) << ',' << to_string(e.status) << '\n';
  }
  if (!out.flush()) throw std::runtime_error("writing '" + path + "' failed");
}

}  // namespace beaconloc

namespace beaconloc {

TruthTrack load_truth_csv(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error("cannot read truth file '" + path + "'");
  TruthTrack truth;
  std::string line;
  std::getline(in, line);
  if (line != "stamp_ns,x_m,y_m,yaw_rad") {
    throw std::runtime_error(path + ":1: expected header stamp_ns,x_m,y_m,yaw_rad");
  }
  for (int n = 2; std::getline(in, line); ++n) {
    long long stamp = 0;
    double x = 0, y = 0, yaw = 0;
    char extra = 0;
    if (std::sscanf(line.c_str(), "%lld,%lf,%lf,%lf%c", &stamp, &x, &y, &yaw, &extra) != 4 ||
        !std::isfinite(x) || !std::isfinite(y) || !std::isfinite(yaw)) {
      throw std::runtime_error(path + ":" + std::to_string(n) + ": malformed truth row '" + line + "'");
    }
    truth.add(stamp, {x, y, yaw});
  }
  return truth;
}

PoseRunSummary summarize(const std::vector<RecordedPose>& poses, const TruthTrack& truth) {
  PoseRunSummary s;
  s.poses = poses.size();
  if (poses.size() >= 2) {
    const double span_s =
        std::chrono::duration<double>(poses.back().received - poses.front().received).count();
    if (span_s > 0.0) s.pose_rate_hz = static_cast<double>(poses.size() - 1) / span_s;
  }
  for (const auto& p : poses) {
    const auto t = truth.at(p.estimate.stamp_ns);
    if (!t) {
      ++s.poses_without_truth;
      continue;
    }
    s.error.add(*t, p.estimate.pose_map_base);
  }
  return s;
}

}  // namespace beaconloc
