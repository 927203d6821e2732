#include "beaconloc/dds/checked_type.hpp"

#include <algorithm>

namespace beaconloc::dds {
namespace {

bool printable(const std::string& s) {
  return std::none_of(s.begin(), s.end(), [](char c) {
    const auto u = static_cast<unsigned char>(c);
    return u < 0x20 || u == 0x7f;
  });
}

bool defined(msg::RangeAssociation a) {
  switch (a) {
    case msg::RANGE_ASSOCIATION_BY_ID:
    case msg::RANGE_ASSOCIATION_UNASSOCIATED:
      return true;
  }
  return false;
}

bool defined(msg::PoseStatus s) {
  switch (s) {
    case msg::POSE_STATUS_INITIALIZING:
    case msg::POSE_STATUS_OK:
    case msg::POSE_STATUS_DEGRADED:
    case msg::POSE_STATUS_LOST:
      return true;
  }
  return false;
}

bool defined(msg::ParticipantStatus s) {
  switch (s) {
    case msg::PARTICIPANT_STATUS_OK:
    case msg::PARTICIPANT_STATUS_DEGRADED:
    case msg::PARTICIPANT_STATUS_ERROR:
      return true;
  }
  return false;
}

}  // namespace

bool well_formed(const msg::RawTof& m) { return printable(m.robot_id()); }

bool well_formed(const msg::BeaconRange& m) { return printable(m.robot_id()) && defined(m.association()); }

bool well_formed(const msg::Odometry& m) { return printable(m.robot_id()); }

bool well_formed(const msg::LaserScan& m) { return printable(m.robot_id()); }

bool well_formed(const msg::PoseEstimate& m) {
  return printable(m.robot_id()) && printable(m.estimator()) && defined(m.status());
}

bool well_formed(const msg::InitialPose& m) { return printable(m.robot_id()); }

bool well_formed(const msg::BeaconMap& m) { return printable(m.frame_id()); }

bool well_formed(const msg::Diagnostics& m) {
  if (!printable(m.participant()) || !printable(m.message()) || !defined(m.status())) return false;
  for (const auto& r : m.rejected()) {
    if (!printable(r.reason())) return false;
  }
  return std::all_of(m.robots_localized().begin(), m.robots_localized().end(),
                     [](const std::string& robot) { return printable(robot); });
}

}  // namespace beaconloc::dds
