#include "beaconloc/core/beacon_map_sources.hpp"

#include <algorithm>
#include <vector>

namespace beaconloc {

void BeaconMapSources::on_map(const std::string& writer, const BeaconMap& map) {
  if (std::find(gone_.begin(), gone_.end(), writer) != gone_.end()) return;
  by_writer_[writer] = map;
  count_distinct_maps();
}

void BeaconMapSources::on_writer_gone(const std::string& writer) {
  by_writer_.erase(writer);
  gone_.push_back(writer);
  if (gone_.size() > kKeptGone) gone_.pop_front();
  count_distinct_maps();
}

void BeaconMapSources::count_distinct_maps() {
  std::vector<const BeaconMap*> distinct;
  for (const auto& [writer, map] : by_writer_) {
    bool seen = false;
    for (const BeaconMap* d : distinct) seen = seen || *d == map;
    if (!seen) distinct.push_back(&map);
  }
  distinct_maps_ = distinct.size();
}

std::optional<BeaconMap> BeaconMapSources::agreed_map() const {
  if (distinct_maps_ != 1) return std::nullopt;
  return by_writer_.begin()->second;
}

std::string BeaconMapSources::describe() const {
  return std::to_string(by_writer_.size()) + " writers publish " + std::to_string(distinct_maps_) +
         " different beacon maps";
}

}  // namespace beaconloc
