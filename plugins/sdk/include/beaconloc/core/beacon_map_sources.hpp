#pragma once
// Who publishes the beacon map, and whether they agree. The map topic keeps each writer's newest
// map; a participant takes whichever arrives last. Two live gateways with different maps (a
// misconfigured site, a gateway started with the wrong scenario) would flip a robot between two
// beacon layouts silently: they are a conflict to report instead (Diagnostics degraded, naming
// it, and no pose "ok": one of the maps is wrong), until all but one writer are gone or they
// publish the same map; then the map they agree on is the one to use. Keyed by writer id;
// bounded by the writers the bus matches. DDS-free.
#include <cstddef>
#include <deque>
#include <map>
#include <optional>
#include <string>

#include "beaconloc/core/beacon_map.hpp"

namespace beaconloc {

class BeaconMapSources {
 public:
  // A map taken from `writer` (a refused one is not a source). A writer that has gone is no source
  // either: its last map and its leaving may be told on two threads in either order.
  void on_map(const std::string& writer, const BeaconMap& map);
  // The writer left the bus (unmatched, or its liveliness lapsed). Writer ids are never reused.
  void on_writer_gone(const std::string& writer);
  // How many different maps the live writers publish (0 before any map, 1 when they agree).
  std::size_t distinct_maps() const { return distinct_maps_; }
  bool disagree() const { return distinct_maps_ > 1; }
  // The one map every live writer publishes; nullopt when none does or they disagree.
  std::optional<BeaconMap> agreed_map() const;
  // "N writers publish M different beacon maps", for a Diagnostics message.
  std::string describe() const;

 private:
  void count_distinct_maps();
  std::map<std::string, BeaconMap> by_writer_;
  std::size_t distinct_maps_ = 0;
  // The writers gone, newest kKeptGone (a gateway restarted every minute for a year is 5e5 ids).
  static constexpr std::size_t kKeptGone = 4096;
  std::deque<std::string> gone_;
};

}  // namespace beaconloc
