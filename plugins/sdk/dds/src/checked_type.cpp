#include "beaconloc/dds/checked_type.hpp"

#include <algorithm>

namespace beaconloc::dds {
namespace {

// No C0 control (0x00-0x1f), no DEL, no C1 control (U+0080-U+009F, 0xc2 0x80-0x9f in UTF-8: CSI
// and its kin move a terminal's cursor as ESC [ does). Other UTF-8 is text like any other.
bool printable(const std::string& s) {
  for (std::size_t i = 0; i < s.size(); ++i) {
    const auto u = static_cast<unsigned char>(s[i]);
    if (u < 0x20 || u == 0x7f) return false;
    if (u == 0xc2 && i + 1 < s.size()) {
      const auto next = static_cast<unsigned char>(s[i + 1]);
      if (next >= 0x80 && next <= 0x9f) return false;
    }
  }
  return true;
}

// A name that is also a CSV cell as the files write it (unquoted): printable, no ',' and no '"'.
bool identifier(const std::string& s) {
  return printable(s) && s.find_first_of(",\"") == std::string::npos;
}

bool defined(msg::PulseMark m) {
  switch (m) {
    case msg::PULSE_MARK_NOT_REPORTED:
    case msg::PULSE_MARK_SINGLE:
    case msg::PULSE_MARK_DOUBLE:
      return true;
  }
  return false;
}

bool defined(msg::BeaconFrame f) {
  switch (f) {
    case msg::BEACON_FRAME_MAP:
    case msg::BEACON_FRAME_GROUP:
      return true;
  }
  return false;
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

bool well_formed(const msg::RawTof& m) { return identifier(m.robot_id()); }

bool well_formed(const msg::PulseArrival& m) { return identifier(m.robot_id()) && defined(m.mark()); }

bool well_formed(const msg::BeaconRange& m) { return identifier(m.robot_id()) && defined(m.association()); }

bool well_formed(const msg::Odometry& m) { return identifier(m.robot_id()); }

bool well_formed(const msg::LaserScan& m) { return identifier(m.robot_id()); }

bool well_formed(const msg::PoseEstimate& m) {
  return identifier(m.robot_id()) && identifier(m.estimator()) && defined(m.status());
}

bool well_formed(const msg::EstimatorState& m) {
  if (!identifier(m.robot_id()) || !identifier(m.estimator())) return false;
  for (const msg::EstimatorStateValue& v : m.values()) {
    if (!identifier(v.name())) return false;
  }
  return true;
}

bool well_formed(const msg::InitialPose& m) { return identifier(m.robot_id()); }

bool well_formed(const msg::BeaconMap& m) {
  return printable(m.frame_id()) &&
         std::all_of(m.beacons().begin(), m.beacons().end(), [](const msg::Beacon& b) { return defined(b.frame()); });
}

bool well_formed(const msg::BeaconCalibration& m) { return printable(m.frame_id()); }

bool well_formed(const msg::Diagnostics& m) {
  if (!identifier(m.participant()) || !printable(m.message()) || !defined(m.status())) return false;
  for (const auto& r : m.rejected()) {
    if (!printable(r.reason())) return false;
  }
  return std::all_of(m.robots_localized().begin(), m.robots_localized().end(),
                     [](const std::string& robot) { return identifier(robot); });
}

}  // namespace beaconloc::dds
