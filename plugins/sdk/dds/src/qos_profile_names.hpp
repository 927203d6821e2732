#pragma once
// The profile names a Fast DDS XML profiles file defines, checked before Fast DDS loads it.
// Fast DDS 2.9 meets a profile name that is already defined (built in, or by an earlier file)
// by logging an error, keeping the first definition and returning RETCODE_OK: a QoS file that
// redefines `beaconloc.loopback` or `raw_tof.writer` ran on with the built-in one. Here such a
// file is refused, naming the profile.
#include <set>
#include <string>
#include <utility>

namespace beaconloc::dds {

class QosProfileNames {
 public:
  // Records the profiles (participant, data_writer / publisher, data_reader / subscriber, topic)
  // and transport ids `xml` defines. Throws DdsError naming `origin`, when the text is not XML or
  // defines a name twice, or one already defined: by an earlier add, or already known to Fast
  // DDS (loaded by other code).
  void add(const std::string& xml, const std::string& origin);

 private:
  std::set<std::pair<std::string, std::string>> defined_;  // (kind, name)
};

}  // namespace beaconloc::dds
