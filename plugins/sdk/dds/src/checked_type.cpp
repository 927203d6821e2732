#include "beaconloc/dds/checked_type.hpp"

namespace beaconloc::dds {

bool defines_every_enum(const msg::BeaconRange& m) {
  switch (m.association()) {
    case msg::RANGE_ASSOCIATION_BY_ID:
    case msg::RANGE_ASSOCIATION_UNASSOCIATED:
      return true;
  }
  return false;
}

bool defines_every_enum(const msg::PoseEstimate& m) {
  switch (m.status()) {
    case msg::POSE_STATUS_INITIALIZING:
    case msg::POSE_STATUS_OK:
    case msg::POSE_STATUS_DEGRADED:
    case msg::POSE_STATUS_LOST:
      return true;
  }
  return false;
}

bool defines_every_enum(const msg::Diagnostics& m) {
  switch (m.status()) {
    case msg::PARTICIPANT_STATUS_OK:
    case msg::PARTICIPANT_STATUS_DEGRADED:
    case msg::PARTICIPANT_STATUS_ERROR:
      return true;
  }
  return false;
}

}  // namespace beaconloc::dds
