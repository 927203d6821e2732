#include "beaconloc/core/beacon_map_sources.hpp"

#include <vector>

namespace beaconloc {

void BeaconMapSources::on_map(const std::string& writer, const BeaconMap& map) { by_writer_[writer] = map; }

void BeaconMapSources::on_writer_gone(const std::string& writer) { by_writer_.erase(writer); }

std::size_t BeaconMapSources::distinct_maps() const {
  std::vector<const BeaconMap*> distinct;
  for (const auto& [writer, map] : by_writer_) {
    bool seen = false;
    for (const BeaconMap* d : distinct) seen = seen || *d == map;
    if (!seen) distinct.push_back(&map);
  }
  return distinct.size();
}

std::string BeaconMapSources::describe() const {
  return std::to_string(by_writer_.size()) + " writers publish " + std::to_string(distinct_maps()) +
         " different beacon maps";
}

}  // namespace beaconloc
