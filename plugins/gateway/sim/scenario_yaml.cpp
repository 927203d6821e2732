#include "scenario_yaml.hpp"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <set>
#include <sstream>
#include <type_traits>

#include "beaconloc/core/limits.hpp"
#include "beaconloc/core/yaml_document.hpp"

namespace beaconloc::sim {
namespace {

// A mapping node with the dotted key path that leads to it, for messages, and the keys a
// schema allows there.
class Section {
 public:
  Section(const YAML::Node& node, std::string path, std::string origin, std::set<std::string> allowed)
      : node_(node), path_(std::move(path)), origin_(std::move(origin)) {
    if (!node_.IsMap()) fail(path_.empty() ? "the document" : path_, "must be a mapping", node_);
    for (const auto& kv : node_) {
      if (!kv.first.IsScalar())
        fail(path_.empty() ? "the document" : path_, "has a key that is not a name", kv.first);
      const std::string key = kv.first.as<std::string>();
      if (!allowed.count(key)) fail(join(key), "is not a known key", kv.first);
    }
  }

  bool has(const std::string& key) const { return node_[key] && !node_[key].IsNull(); }

  template <class T>
  T get(const std::string& key, T fallback) const {
    return has(key) ? as<T>(node_[key], join(key)) : fallback;
  }
  template <class T>
  T required(const std::string& key) const {
    if (!has(key)) fail(join(key), "is required", node_);
    return as<T>(node_[key], join(key));
  }
  double number(const std::string& key, double fallback, double min, double max) const {
    const double v = get<double>(key, fallback);
    within(join(key), v, min, max, node_[key] ? node_[key] : node_);
    return v;
  }
  // A whole number: "count: 3.5" is refused, not truncated.
  int integer(const std::string& key, int fallback, int min, int max) const {
    const int v = get<int>(key, fallback);
    within(join(key), v, min, max, node_[key] ? node_[key] : node_);
    return v;
  }
  void within(const std::string& what, double v, double min, double max, const YAML::Node& at) const {
    if (!std::isfinite(v) || v < min || v > max) {
      std::ostringstream range;
      range << "must be in [" << min << ", " << max << "], got " << v;
      fail(what, range.str(), at);
    }
  }
  Section child(const std::string& key, std::set<std::string> allowed) const {
    return Section(node_[key], join(key), origin_, std::move(allowed));
  }
  YAML::Node node(const std::string& key) const { return node_[key]; }
  std::string join(const std::string& key) const { return path_.empty() ? key : path_ + "." + key; }
  const std::string& origin() const { return origin_; }

  [[noreturn]] void fail(const std::string& what, const std::string& why, const YAML::Node& at) const {
    std::ostringstream msg;
    msg << origin_;
    // A missing key has no place of its own: point at the mapping that lacks it.
    const YAML::Mark mark = at.IsDefined() ? at.Mark() : node_.Mark();
    if (mark.line >= 0) msg << ':' << mark.line + 1;
    msg << ": '" << what << "' " << why;
    throw ScenarioError(msg.str());
  }

  // Numbers, and lists of numbers, through the project's one decimal parser; other types
  // (names, booleans) through yaml-cpp.
  template <class T>
  T as(const YAML::Node& n, const std::string& what) const {
    if constexpr (std::is_arithmetic_v<T> && !std::is_same_v<T, bool>) {
      return scalar_number<T>(n, what);
    } else if constexpr (std::is_same_v<T, std::vector<double>> ||
                         std::is_same_v<T, std::vector<std::uint32_t>>) {
      if (!n.IsSequence()) fail(what, "has the wrong type", n);
      T out;
      for (std::size_t i = 0; i < n.size(); ++i) {
        out.push_back(scalar_number<typename T::value_type>(n[i], what + "[" + std::to_string(i) + "]"));
      }
      return out;
    } else {
      try {
        return n.as<T>();
      } catch (const YAML::Exception&) {
        fail(what, "has the wrong type", n);
      }
    }
  }
  template <class T>
  T scalar_number(const YAML::Node& n, const std::string& what) const {
    if (!n.IsScalar()) fail(what, "has the wrong type", n);
    T v{};
    const NumberError e = yaml_number(n, v);
    if (e != NumberError::kNone) fail(what, std::string(describe(e)) + " ('" + n.Scalar() + "')", n);
    return v;
  }

 private:
  YAML::Node node_;
  std::string path_;
  std::string origin_;
};

// [x, y], each within [-limit, limit].
Eigen::Vector2d vec2(const Section& s, const YAML::Node& n, const std::string& what, double limit) {
  const auto v = s.as<std::vector<double>>(n, what);
  if (v.size() != 2) s.fail(what, "must be [x, y]", n);
  for (std::size_t i = 0; i < 2; ++i) s.within(what + "[" + std::to_string(i) + "]", v[i], -limit, limit, n);
  return {v[0], v[1]};
}

// Three numbers, each within [-limit, limit].
Eigen::Vector3d vec3(const Section& s, const YAML::Node& n, const std::string& what, double limit) {
  const auto v = s.as<std::vector<double>>(n, what);
  if (v.size() != 3) s.fail(what, "must be three finite numbers", n);
  for (std::size_t i = 0; i < 3; ++i) s.within(what + "[" + std::to_string(i) + "]", v[i], -limit, limit, n);
  return {v[0], v[1], v[2]};
}

StampNs duration_ns(const Section& s, const std::string& key, double fallback_s) {
  return s_to_ns(s.number(key, fallback_s, 1e-4, 3600.0));
}

void read_beacons(const Section& root, Scenario& sc) {
  if (!root.has("beacons") || !root.node("beacons").IsSequence() || root.node("beacons").size() == 0) {
    root.fail("beacons", "is required: a list of at least one beacon", root.node("beacons"));
  }
  std::set<std::uint32_t> ids;
  const YAML::Node list = root.node("beacons");
  for (std::size_t i = 0; i < list.size(); ++i) {
    const Section b(list[i], "beacons[" + std::to_string(i) + "]", root.origin(),
                    {"id", "position_m", "group"});
    Beacon beacon;
    beacon.id = b.required<std::uint32_t>("id");
    if (beacon.id == kBeaconUnidentified)
      b.fail(b.join("id"), "is reserved for unidentified pulses", list[i]);
    if (!ids.insert(beacon.id).second) b.fail(b.join("id"), "repeats an earlier beacon id", list[i]);
    if (!b.has("position_m")) b.fail(b.join("position_m"), "is required", list[i]);
    beacon.position_map_m = vec3(b, b.node("position_m"), b.join("position_m"), kMaxMapCoordinateM);
    beacon.group = b.get<std::uint32_t>("group", 0);
    sc.beacons.push_back(beacon);
  }
}

// Seed 003's beacon groups: `groups: [{id, referenced: global | local, frame_pose_m: [x, y,
// yaw_deg]}]`, a local group's frame pose being the truth the participants are not told. A group
// not listed is globally referenced.
void read_groups(const Section& root, Scenario& sc) {
  if (!root.has("groups")) return;
  const YAML::Node list = root.node("groups");
  if (!list.IsSequence()) root.fail("groups", "must be a list of groups", list);
  std::set<std::uint32_t> used, listed;
  for (const auto& b : sc.beacons) used.insert(b.group);
  for (std::size_t i = 0; i < list.size(); ++i) {
    const Section g(list[i], "groups[" + std::to_string(i) + "]", root.origin(), {"id", "referenced", "frame_pose_m"});
    const auto id = g.required<std::uint32_t>("id");
    if (id == 0) g.fail(g.join("id"), "is 0, the group of a site with one group: it has no frame of its own", list[i]);
    if (!used.count(id)) g.fail(g.join("id"), "is not the group of any beacon", list[i]);
    if (!listed.insert(id).second) g.fail(g.join("id"), "repeats an earlier group", list[i]);
    const auto referenced = g.required<std::string>("referenced");
    if (referenced == "global") {
      if (g.has("frame_pose_m")) g.fail(g.join("frame_pose_m"), "is for a locally referenced group only", list[i]);
    } else if (referenced == "local") {
      if (!g.has("frame_pose_m")) g.fail(g.join("frame_pose_m"), "is required for a locally referenced group", list[i]);
      const Eigen::Vector3d pose = vec3(g, g.node("frame_pose_m"), g.join("frame_pose_m"), kMaxMapCoordinateM);
      sc.local_group_frames_map[id] = Pose2(pose.x(), pose.y(), wrap_angle_rad(pose.z() * M_PI / 180.0));
    } else {
      g.fail(g.join("referenced"), "must be global or local", list[i]);
    }
  }
}

void read_beacon_system(const Section& root, Scenario& sc) {
  for (const auto& b : sc.beacons) sc.firing_order.push_back(b.id);
  if (!root.has("beacon_system")) return;
  const Section s = root.child(
      "beacon_system", {"slot_period_s", "first_slot_s", "firing_order", "identified", "radio_sync", "marked_beacon_id",
                        "range_sigma_m", "tof_sigma_s", "range_scale", "range_bias_m", "min_range_m", "max_range_m", "beam_half_angle_deg",
                        "group_coverage_radius_m", "temperature_c", "reported_temperature_c", "echo"});
  sc.slot_period_ns = duration_ns(s, "slot_period_s", 0.2);
  sc.first_slot_ns = s_to_ns(s.number("first_slot_s", 0.05, 0.0, 3600.0));
  if (s.has("firing_order")) {
    sc.firing_order = s.as<std::vector<std::uint32_t>>(s.node("firing_order"), s.join("firing_order"));
    if (sc.firing_order.empty()) s.fail(s.join("firing_order"), "must not be empty", s.node("firing_order"));
    for (auto id : sc.firing_order) {
      bool known = false;
      for (const auto& b : sc.beacons) known = known || b.id == id;
      if (!known)
        s.fail(s.join("firing_order"), "names beacon " + std::to_string(id) + ", which is not in beacons",
               s.node("firing_order"));
    }
  }
  sc.identified = s.get<bool>("identified", true);
  sc.radio_sync = s.get<bool>("radio_sync", true);
  if (!sc.radio_sync && sc.identified)
    s.fail(s.join("radio_sync"), "false needs identified: false (a pulse without a radio message carries no id)",
           s.node("radio_sync"));
  if (s.has("marked_beacon_id")) sc.marked_beacon_id = s.get<std::uint32_t>("marked_beacon_id", 0);
  sc.range_sigma_m = s.number("range_sigma_m", 0.01, 0.0, 100.0);
  sc.tof_sigma_s = s.number("tof_sigma_s", 0.0, 0.0, 1.0);
  sc.range_scale = s.number("range_scale", 1.0, 0.5, 2.0);
  sc.range_bias_m = s.number("range_bias_m", 0.0, -10.0, 10.0);
  sc.min_range_m = s.number("min_range_m", 0.0, 0.0, kMaxRangeM);
  sc.max_range_m = s.number("max_range_m", 5.0, 0.0, kMaxRangeM);
  if (sc.max_range_m <= sc.min_range_m)
    s.fail(s.join("max_range_m"), "must exceed min_range_m", s.node("max_range_m"));
  sc.beam_half_angle_rad = s.number("beam_half_angle_deg", 90.0, 0.1, 180.0) * M_PI / 180.0;
  if (s.has("group_coverage_radius_m")) {
    sc.group_coverage_radius_m = s.number("group_coverage_radius_m", 0.0, 0.0, kMaxRangeM);
    if (!(*sc.group_coverage_radius_m > 0.0))
      s.fail(s.join("group_coverage_radius_m"), "must be above 0", s.node("group_coverage_radius_m"));
  }
  sc.temperature_c = s.number("temperature_c", 22.0, -40.0, 60.0);
  if (s.has("reported_temperature_c"))
    sc.reported_temperature_c = s.number("reported_temperature_c", 0.0, -40.0, 60.0);
  if (s.has("echo")) {
    const Section e = s.child("echo", {"probability", "min_extra_path_m", "max_extra_path_m"});
    sc.echo.probability = e.number("probability", 0.0, 0.0, 1.0);
    sc.echo.min_extra_path_m = e.number("min_extra_path_m", 0.3, 0.0, 1e3);
    sc.echo.max_extra_path_m = e.number("max_extra_path_m", 3.0, sc.echo.min_extra_path_m, 1e3);
  }
}

void read_robot(const Section& root, Scenario& sc) {
  if (!root.has("robot")) root.fail("robot", "is required", root.node("robot"));
  const Section r = root.child("robot", {"wheel_base_m", "receivers", "odometry"});
  sc.wheel_base_m = r.number("wheel_base_m", 0.33, 0.01, kMaxWheelBaseM);
  if (!r.has("receivers")) r.fail(r.join("receivers"), "is required", r.node("receivers"));
  const Section rx = r.child("receivers", {"height_m", "positions_m", "circle"});
  if (rx.has("positions_m") == rx.has("circle")) {
    rx.fail(rx.join("positions_m"), "or 'circle' is required, not both", r.node("receivers"));
  }
  if (rx.has("circle")) {
    const Section c = rx.child("circle", {"radius_m", "count"});
    sc.receivers = ReceiverArray::on_circle(c.number("radius_m", 0.19, 0.0, kMaxReceiverOffsetM),
                                            c.integer("count", 3, 1, 16));
  } else {
    const YAML::Node list = rx.node("positions_m");
    if (!list.IsSequence() || list.size() == 0) rx.fail(rx.join("positions_m"), "must list receivers", list);
    sc.receivers.receivers_base_m.clear();
    for (std::size_t i = 0; i < list.size(); ++i) {
      sc.receivers.receivers_base_m.push_back(
          vec2(rx, list[i], rx.join("positions_m") + "[" + std::to_string(i) + "]", kMaxReceiverOffsetM));
    }
  }
  sc.receivers.receiver_height_m = rx.number("height_m", 0.0, -kMaxReceiverOffsetM, kMaxReceiverOffsetM);
  if (r.has("odometry")) {
    const Section o = r.child("odometry", {"period_s", "k_v_m", "alpha", "wheel_radius_error_right",
                                           "wheel_radius_error_left", "wheel_base_error"});
    sc.odometry_period_ns = duration_ns(o, "period_s", 0.01);
    sc.odometry_k_v_m = o.number("k_v_m", 4e-4, 0.0, 1.0);
    sc.wheel_radius_error_right = o.number("wheel_radius_error_right", 0.0, -0.5, 0.5);
    sc.wheel_radius_error_left = o.number("wheel_radius_error_left", 0.0, -0.5, 0.5);
    sc.wheel_base_error = o.number("wheel_base_error", 0.0, -0.5, 0.5);
    if (o.has("alpha")) {
      if (o.has("k_v_m")) o.fail(o.join("alpha"), "and k_v_m exclude each other", o.node("alpha"));
      const auto a = o.as<std::vector<double>>(o.node("alpha"), o.join("alpha"));
      if (a.size() != 4 || *std::min_element(a.begin(), a.end()) < 0.0 ||
          *std::max_element(a.begin(), a.end()) > 10.0) {
        o.fail(o.join("alpha"), "must be four numbers in [0, 10]", o.node("alpha"));
      }
      sc.odometry_alpha = std::array<double, 4>{a[0], a[1], a[2], a[3]};
      sc.odometry_k_v_m = 0.0;
    }
  }
}

void read_trajectory(const Section& root, Scenario& sc) {
  if (!root.has("trajectory")) root.fail("trajectory", "is required", root.node("trajectory"));
  const Section t = root.child(
      "trajectory", {"start_pose", "loop", "segments", "waypoints_m", "speed_mps", "turn_rate_radps"});
  if (t.has("segments") == t.has("waypoints_m")) {
    t.fail(t.join("segments"), "or 'waypoints_m' is required, not both", root.node("trajectory"));
  }
  if (t.has("segments")) {
    const YAML::Node list = t.node("segments");
    if (!list.IsSequence() || list.size() == 0) t.fail(t.join("segments"), "must list segments", list);
    std::vector<VelocitySegment> segments;
    for (std::size_t i = 0; i < list.size(); ++i) {
      const Section s(list[i], t.join("segments") + "[" + std::to_string(i) + "]", root.origin(),
                      {"duration_s", "linear_mps", "angular_radps"});
      if (!s.has("duration_s")) s.fail(s.join("duration_s"), "is required", list[i]);
      segments.push_back({s.number("duration_s", 0.0, 1e-6, 1e5),
                          s.number("linear_mps", 0.0, -kMaxWheelSpeedMps, kMaxWheelSpeedMps),
                          s.number("angular_radps", 0.0, -10.0, 10.0)});
    }
    if (!t.has("start_pose"))
      t.fail(t.join("start_pose"), "is required with segments", root.node("trajectory"));
    sc.trajectory = Trajectory(vec3(t, t.node("start_pose"), t.join("start_pose"), kMaxMapCoordinateM),
                               segments, t.get<bool>("loop", false));
    // The simulator composes a lap once per lap travelled, counted as an int: a bounded number.
    if (sc.trajectory.loops() && sc.duration_s / sc.trajectory.period_s() > 1e6)
      t.fail(t.join("loop"), "would repeat the segments more than 1e6 times in duration_s", t.node("loop"));
    return;
  }
  if (t.has("start_pose") || t.has("loop")) {
    t.fail(t.join("waypoints_m"), "paths start at their first waypoint and do not loop",
           root.node("trajectory"));
  }
  const YAML::Node list = t.node("waypoints_m");
  std::vector<Eigen::Vector2d> waypoints;
  for (std::size_t i = 0; list.IsSequence() && i < list.size(); ++i) {
    waypoints.push_back(
        vec2(t, list[i], t.join("waypoints_m") + "[" + std::to_string(i) + "]", kMaxMapCoordinateM));
  }
  if (!t.has("speed_mps"))
    t.fail(t.join("speed_mps"), "is required with waypoints_m", root.node("trajectory"));
  try {
    sc.trajectory = Trajectory::from_waypoints(waypoints, t.number("speed_mps", 0.0, 1e-3, kMaxWheelSpeedMps),
                                               t.number("turn_rate_radps", 0.5, 1e-3, 10.0));
  } catch (const std::invalid_argument& e) {
    t.fail(t.join("waypoints_m"), e.what(), list);
  }
}

void read_map_and_laser(const Section& root, Scenario& sc) {
  if (root.has("map")) {
    const Section m = root.child(
        "map", {"resolution_m", "origin_m", "size_m", "border", "obstacles", "unmapped_obstacles",
                "world_resolution_m"});
    const double res =
        m.number("resolution_m", 0.1, OccupancyGrid::kMinResolutionM, OccupancyGrid::kMaxResolutionM);
    if (!m.has("size_m")) m.fail(m.join("size_m"), "is required", root.node("map"));
    const Eigen::Vector2d size = vec2(m, m.node("size_m"), m.join("size_m"), kMaxMapCoordinateM);
    if (size.minCoeff() <= 0.0 || size.maxCoeff() / res > OccupancyGrid::kMaxCellsPerSide ||
        (size.x() / res) * (size.y() / res) > static_cast<double>(OccupancyGrid::kMaxCells)) {
      std::ostringstream limits;
      limits << "must be positive and at most " << OccupancyGrid::kMaxCellsPerSide << " cells a side, "
             << OccupancyGrid::kMaxCells << " cells in all";
      m.fail(m.join("size_m"), limits.str(), m.node("size_m"));
    }
    const Eigen::Vector2d origin = m.has("origin_m")
                                       ? vec2(m, m.node("origin_m"), m.join("origin_m"), kMaxMapCoordinateM)
                                       : Eigen::Vector2d::Zero();
    const int width = static_cast<int>(std::ceil(size.x() / res - 1e-9));
    const int height = static_cast<int>(std::ceil(size.y() / res - 1e-9));
    if (width < 1 || height < 1)
      m.fail(m.join("size_m"), "must be at least one cell a side", m.node("size_m"));
    const bool border = m.get<bool>("border", true);
    OccupancyGrid grid(origin, res, width, height);
    if (border) grid.fill_border();
    auto fill = [&](const char* key, OccupancyGrid& target) {
      const YAML::Node list = m.node(key);
      for (std::size_t i = 0; list && list.IsSequence() && i < list.size(); ++i) {
        const Section o(list[i], m.join(key) + "[" + std::to_string(i) + "]", root.origin(),
                        {"min_m", "max_m"});
        if (!o.has("min_m") || !o.has("max_m")) o.fail(o.join("min_m"), "and max_m are required", list[i]);
        const Eigen::Vector2d lo = vec2(o, o.node("min_m"), o.join("min_m"), kMaxMapCoordinateM),
                              hi = vec2(o, o.node("max_m"), o.join("max_m"), kMaxMapCoordinateM);
        if ((hi.array() <= lo.array()).any()) o.fail(o.join("max_m"), "must exceed min_m", list[i]);
        target.fill_rectangle(lo, hi);
      }
    };
    fill("obstacles", grid);
    sc.map = grid;
    if (m.has("world_resolution_m")) {
      // The room as built, on its own finer grid: the same obstacles, their faces where the
      // coordinates put them rather than on the map's cell edges.
      const double world_res = m.number("world_resolution_m", res, OccupancyGrid::kMinResolutionM, res);
      if ((size.x() / world_res) * (size.y() / world_res) > static_cast<double>(OccupancyGrid::kMaxCells) ||
          size.maxCoeff() / world_res > OccupancyGrid::kMaxCellsPerSide) {
        m.fail(m.join("world_resolution_m"), "makes too many cells for the map's size", m.node("world_resolution_m"));
      }
      OccupancyGrid world(origin, world_res, static_cast<int>(std::ceil(size.x() / world_res - 1e-9)),
                          static_cast<int>(std::ceil(size.y() / world_res - 1e-9)));
      if (border) world.fill_border();
      fill("obstacles", world);
      sc.world = world;
    }
    if (m.has("unmapped_obstacles")) {  // in the world the laser sees, not in the map
      OccupancyGrid world = sc.world ? *sc.world : grid;
      fill("unmapped_obstacles", world);
      sc.world = world;
    }
  }
  if (root.has("laser")) {
    if (!sc.map) root.fail("laser", "needs a map to cast its rays on", root.node("laser"));
    const Section l =
        root.child("laser", {"beams", "fov_deg", "period_s", "range_sigma_m", "systematic_error_m",
                             "spot_diameter_at_window_m", "spot_divergence_rad", "echo_merge_m", "max_range_m",
                             "mount_m"});
    LaserModel laser;
    laser.beams = l.integer("beams", 19, 1, 4096);
    laser.fov_rad = l.number("fov_deg", 180.0, 0.0, 360.0) * M_PI / 180.0;
    laser.period_ns = duration_ns(l, "period_s", 0.022);
    laser.range_sigma_m = l.number("range_sigma_m", 0.1, 0.0, 10.0);
    laser.systematic_error_m = l.number("systematic_error_m", 0.0, 0.0, 10.0);
    laser.spot.diameter_at_window_m = l.number("spot_diameter_at_window_m", 0.0, 0.0, 1.0);
    laser.spot.divergence_rad = l.number("spot_divergence_rad", 0.0, 0.0, 0.1);
    laser.spot.echo_merge_m = l.number("echo_merge_m", 0.0, 0.0, 10.0);
    laser.max_range_m = l.number("max_range_m", 8.0, 0.01, 1e3);
    if (l.has("mount_m"))
      laser.mount_base = vec3(l, l.node("mount_m"), l.join("mount_m"), kMaxReceiverOffsetM);
    sc.laser = laser;
  }
}

// People walking (Walker): each a path of at least two points, a speed and a radius. At most
// kMaxPeople of kMaxPathPoints each: every scan casts its rays against every one.
constexpr std::size_t kMaxPeople = 100;
constexpr std::size_t kMaxPathPoints = 1000;

void read_people(const Section& root, Scenario& sc) {
  if (!root.has("people")) return;
  const YAML::Node list = root.node("people");
  if (!list.IsSequence()) root.fail("people", "must list walkers", list);
  if (list.size() > kMaxPeople) root.fail("people", "may list at most " + std::to_string(kMaxPeople) + " walkers", list);
  for (std::size_t i = 0; i < list.size(); ++i) {
    const Section w(list[i], "people[" + std::to_string(i) + "]", root.origin(),
                    {"path_m", "speed_mps", "radius_m"});
    const YAML::Node path = w.node("path_m");
    if (!path || !path.IsSequence() || path.size() < 2 || path.size() > kMaxPathPoints) {
      w.fail(w.join("path_m"), "must list 2 to " + std::to_string(kMaxPathPoints) + " points", list[i]);
    }
    std::vector<Eigen::Vector2d> points;
    for (std::size_t k = 0; k < path.size(); ++k) {
      points.push_back(vec2(w, path[k], w.join("path_m") + "[" + std::to_string(k) + "]", kMaxMapCoordinateM));
    }
    const double speed = w.number("speed_mps", 1.0, 1e-3, 10.0);
    const double radius = w.number("radius_m", 0.2, 0.01, 5.0);
    try {
      sc.people.emplace_back(std::move(points), speed, radius);
    } catch (const std::invalid_argument& e) {
      w.fail(w.join("path_m"), e.what(), list[i]);
    }
  }
}

}  // namespace

Scenario parse_scenario(const std::string& yaml_text, const std::string& origin) {
  YAML::Node doc;
  try {
    doc = load_yaml(yaml_text, origin);
  } catch (const YamlError& e) {
    throw ScenarioError(e.what());
  }
  const Section root(doc, "", origin,
                     {"name", "description", "seed", "duration_s", "score_from_s", "beacons", "groups",
                      "beacon_system", "robot", "trajectory", "map", "laser", "people"});
  Scenario sc;
  sc.name = root.required<std::string>("name");
  sc.description = root.get<std::string>("description", "");
  sc.seed = root.get<std::uint64_t>("seed", 1);
  sc.duration_s = root.number("duration_s", 20.0, 0.01, kMaxDurationS);
  sc.score_from_s = root.number("score_from_s", 0.0, 0.0, sc.duration_s);
  read_beacons(root, sc);
  read_groups(root, sc);
  read_beacon_system(root, sc);
  read_robot(root, sc);
  read_trajectory(root, sc);
  read_map_and_laser(root, sc);
  read_people(root, sc);
  return sc;
}

Scenario load_scenario_file(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw ScenarioError("cannot read scenario file '" + path + "'");
  std::stringstream text;
  text << in.rdbuf();
  return parse_scenario(text.str(), path);
}

}  // namespace beaconloc::sim
