#pragma once
// Participants and writers as the DDS-free code names them: a writer's id is the hex text of its
// 16-octet GUID (dds::writer_id), and every writer of one participant begins with the same 12
// octets, the participant's GUID prefix: its id here.
#include <string>

namespace beaconloc {

// The participant a writer belongs to: the first 24 hex digits (12 octets) of its id.
inline std::string participant_of_writer(const std::string& writer_id) { return writer_id.substr(0, 24); }

}  // namespace beaconloc
