// The rosbag2 writer, read back three ways that share nothing with it: the sqlite3 C API,
// yaml-cpp, and the independent reader tests/tools/check_rosbag2.py. Messages are built here by
// hand (a little-endian CDR builder of the test's own), so a wrong layout shows in the reader.
#include "rosbag2_writer.hpp"

#include <gtest/gtest.h>
#include <signal.h>
#include <sqlite3.h>
#include <sys/mman.h>
#include <sys/wait.h>
#include <unistd.h>
#include <yaml-cpp/yaml.h>

#include <array>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <limits>
#include <memory>
#include <new>
#include <set>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

namespace beaconloc::rosbag2 {
namespace {

namespace fs = std::filesystem;
using Bytes = std::vector<std::uint8_t>;
using Rows = std::vector<std::vector<std::string>>;

constexpr const char* kPoseType = "geometry_msgs/msg/PoseWithCovarianceStamped";
constexpr const char* kOdometryType = "nav_msgs/msg/Odometry";
constexpr std::int64_t kT0 = 1'700'000'000'000'000'000;  // ns since the epoch

// offered_qos_profiles as Humble writes them (rosbag2's own test bags), infinite durations.
std::string expected_qos(int reliability, int durability, int depth) {
  const std::string infinite = "\n    sec: 9223372036\n    nsec: 854775807";
  return "- history: 1\n  depth: " + std::to_string(depth) +
         "\n  reliability: " + std::to_string(reliability) + "\n  durability: " + std::to_string(durability) +
         "\n  deadline:" + infinite + "\n  lifespan:" + infinite +
         "\n  liveliness: 1\n  liveliness_lease_duration:" + infinite +
         "\n  avoid_ros_namespace_conventions: false";
}

// CDR little endian: the encapsulation header 00 01 00 00, then each primitive aligned to its size
// counted from the first byte after the header; strings are a uint32 length counting the NUL.
class Cdr {
 public:
  Cdr& u32(std::uint32_t v) {
    align(4);
    for (int i = 0; i < 4; ++i) bytes_.push_back(static_cast<std::uint8_t>(v >> (8 * i)));
    return *this;
  }
  Cdr& i32(std::int32_t v) { return u32(static_cast<std::uint32_t>(v)); }
  Cdr& f64(double v) {
    align(8);
    std::uint64_t bits = 0;
    std::memcpy(&bits, &v, sizeof bits);
    for (int i = 0; i < 8; ++i) bytes_.push_back(static_cast<std::uint8_t>(bits >> (8 * i)));
    return *this;
  }
  template <std::size_t N>
  Cdr& f64s(const std::array<double, N>& values) {
    for (const double v : values) f64(v);
    return *this;
  }
  Cdr& str(const std::string& s) {
    u32(static_cast<std::uint32_t>(s.size() + 1));
    bytes_.insert(bytes_.end(), s.begin(), s.end());
    bytes_.push_back(0);
    return *this;
  }
  Bytes bytes() const { return bytes_; }

 private:
  void align(std::size_t n) {
    while ((bytes_.size() - 4) % n != 0) bytes_.push_back(0);
  }
  Bytes bytes_{0x00, 0x01, 0x00, 0x00};
};

struct Pose {  // geometry_msgs/msg/PoseWithCovarianceStamped
  std::int32_t sec;
  std::uint32_t nanosec;
  std::string frame_id;
  std::array<double, 7> pose;  // x y z qx qy qz qw
  std::array<double, 36> cov;
  std::int64_t received_ns;
};

struct Odometry {  // nav_msgs/msg/Odometry
  std::int32_t sec;
  std::uint32_t nanosec;
  std::string frame_id;
  std::string child_frame_id;
  std::array<double, 7> pose;
  std::array<double, 6> twist;  // vx vy vz wx wy wz
  std::array<double, 36> pose_cov;
  std::array<double, 36> twist_cov;
  std::int64_t received_ns;
};

std::int64_t header_ns(std::int32_t sec, std::uint32_t nanosec) {
  return std::int64_t{sec} * 1'000'000'000 + nanosec;
}

Bytes cdr(const Pose& p) {
  return Cdr().i32(p.sec).u32(p.nanosec).str(p.frame_id).f64s(p.pose).f64s(p.cov).bytes();
}

Bytes cdr(const Odometry& o) {
  return Cdr()
      .i32(o.sec)
      .u32(o.nanosec)
      .str(o.frame_id)
      .str(o.child_frame_id)
      .f64s(o.pose)
      .f64s(o.pose_cov)
      .f64s(o.twist)
      .f64s(o.twist_cov)
      .bytes();
}

// Symmetric, with negative and non-representable-in-decimal entries.
std::array<double, 36> covariance(double scale) {
  std::array<double, 36> c{};
  for (int r = 0; r < 6; ++r) {
    for (int col = r; col < 6; ++col) {
      const double v = r == col ? scale * (r + 1) / 3.0 : -scale * 0.1 * (r + 1) + 0.01 * col;
      c[static_cast<std::size_t>(r * 6 + col)] = v;
      c[static_cast<std::size_t>(col * 6 + r)] = v;
    }
  }
  return c;
}

std::array<double, 7> pose_values(double k) {
  const double yaw = -0.7 + k;
  return {-3.25 + k, 1.0 / 3.0 * (k + 1), k == 0 ? -0.0 : -k * 1e-7, 0.0,
          0.0,       std::sin(yaw / 2),   std::cos(yaw / 2)};
}

struct ChosenValues {
  std::vector<Pose> poses;
  std::vector<Odometry> odometry;
};

ChosenValues chosen_values() {
  ChosenValues v;
  // Received out of order once (odometry 0 before pose 0), and pose 2 two and a half seconds later.
  const std::array<std::int64_t, 3> pose_received{kT0 + 10'000'000, kT0 + 20'000'000, kT0 + 2'500'000'000};
  for (int i = 0; i < 3; ++i) {
    const double k = i;
    v.poses.push_back({1'700'000'000 + i, 123'456'789u + static_cast<std::uint32_t>(i), "map", pose_values(k),
                       covariance(0.5 + k), pose_received[static_cast<std::size_t>(i)]});
  }
  const std::array<std::int64_t, 2> odometry_received{kT0 + 5'000'000, kT0 + 25'000'000};
  for (int i = 0; i < 2; ++i) {
    const double k = i;
    v.odometry.push_back({1'700'000'000 + i,
                          999'999'999u - static_cast<std::uint32_t>(i),
                          "odom",
                          "base_link",
                          pose_values(k + 0.5),
                          {0.25 - k, -0.125, 0.0, -1e-3, 2e-3, -0.75 + k},
                          covariance(2.0 + k),
                          covariance(-0.001 - k),
                          odometry_received[static_cast<std::size_t>(i)]});
  }
  return v;
}

struct Written {
  int topic_id;
  std::int64_t received_ns;
  Bytes data;
};

// The order the writer gets them: pose 0, odometry 0, pose 1, odometry 1, pose 2.
std::vector<Written> write_chosen_bag(const fs::path& dir, const ChosenValues& v) {
  Rosbag2Writer writer(dir.string());
  const int pose_topic = writer.add_topic("/beacon_pose", kPoseType, TopicQos{true, false, 10});
  const int odometry_topic = writer.add_topic("/odom", kOdometryType, TopicQos{false, true, 5});
  std::vector<Written> written;
  for (std::size_t i = 0; i < 3; ++i) {
    written.push_back({pose_topic, v.poses[i].received_ns, cdr(v.poses[i])});
    if (i < 2) written.push_back({odometry_topic, v.odometry[i].received_ns, cdr(v.odometry[i])});
  }
  for (const Written& w : written) writer.write(w.topic_id, w.received_ns, w.data.data(), w.data.size());
  EXPECT_EQ(writer.message_count(), 5u);
  writer.close();
  return written;
}

// ---------------------------------------------------------------- reading back

class Db {
 public:
  explicit Db(const std::string& path, int flags = SQLITE_OPEN_READONLY) {
    if (sqlite3_open_v2(path.c_str(), &db_, flags, nullptr) != SQLITE_OK) {
      error_ = db_ != nullptr ? sqlite3_errmsg(db_) : "out of memory";
    }
  }
  ~Db() { sqlite3_close(db_); }
  Db(const Db&) = delete;
  Db& operator=(const Db&) = delete;

  bool ok() const { return error_.empty(); }
  const std::string& error() const { return error_; }

  // Every cell as text, blobs as their bytes; false (and error()) when sqlite fails.
  bool query(const std::string& sql, Rows& rows) {
    rows.clear();
    if (!ok()) return false;
    sqlite3_stmt* stmt = nullptr;
    if (sqlite3_prepare_v2(db_, sql.c_str(), -1, &stmt, nullptr) != SQLITE_OK) {
      error_ = sqlite3_errmsg(db_);
      return false;
    }
    int rc = SQLITE_ROW;
    while ((rc = sqlite3_step(stmt)) == SQLITE_ROW) {
      std::vector<std::string> row;
      for (int c = 0; c < sqlite3_column_count(stmt); ++c) {
        const void* cell = sqlite3_column_type(stmt, c) == SQLITE_BLOB ? sqlite3_column_blob(stmt, c)
                                                                       : sqlite3_column_text(stmt, c);
        const auto size = static_cast<std::size_t>(sqlite3_column_bytes(stmt, c));
        row.emplace_back(cell == nullptr ? std::string() : std::string(static_cast<const char*>(cell), size));
      }
      rows.push_back(std::move(row));
    }
    if (rc != SQLITE_DONE) error_ = sqlite3_errmsg(db_);
    sqlite3_finalize(stmt);
    return rc == SQLITE_DONE;
  }

  Rows rows(const std::string& sql) {
    Rows out;
    EXPECT_TRUE(query(sql, out)) << sql << ": " << error_;
    return out;
  }

  void set_message_data(int id, const Bytes& data) {
    sqlite3_stmt* stmt = nullptr;
    ASSERT_EQ(sqlite3_prepare_v2(db_, "UPDATE messages SET data = ? WHERE id = ?", -1, &stmt, nullptr),
              SQLITE_OK);
    sqlite3_bind_blob(stmt, 1, data.data(), static_cast<int>(data.size()), SQLITE_TRANSIENT);
    sqlite3_bind_int(stmt, 2, id);
    EXPECT_EQ(sqlite3_step(stmt), SQLITE_DONE) << sqlite3_errmsg(db_);
    sqlite3_finalize(stmt);
  }

 private:
  sqlite3* db_ = nullptr;
  std::string error_;
};

std::string text(const Bytes& b) { return std::string(b.begin(), b.end()); }

std::int64_t message_rows(const fs::path& db_path) {
  Db db(db_path.string());
  Rows rows;
  if (!db.query("SELECT COUNT(*) FROM messages", rows) || rows.size() != 1) return -1;
  return std::stoll(rows[0][0]);
}

std::set<std::string> entries(const fs::path& dir) {
  std::set<std::string> names;
  for (const auto& e : fs::directory_iterator(dir)) names.insert(e.path().filename().string());
  return names;
}

YAML::Node bag_info(const fs::path& dir) {
  return YAML::LoadFile((dir / "metadata.yaml").string())["rosbag2_bagfile_information"];
}

// ---------------------------------------------------------------- the independent reader

struct CheckerRun {
  int status;  // exit status, -1 when it did not exit
  std::string output;
};

CheckerRun run_checker(const fs::path& bag, const std::string& arguments) {
  const fs::path log = bag.parent_path() / (bag.filename().string() + "_checker.log");
  const std::string command = std::string(BEACONLOC_SYSTEM_PYTHON3) + " '" + BEACONLOC_CHECK_ROSBAG2 + "' '" +
                              bag.string() + "' " + arguments + " > '" + log.string() + "' 2>&1";
  const int raw = std::system(command.c_str());
  std::ifstream in(log);
  std::stringstream output;
  output << in.rdbuf();
  return {WIFEXITED(raw) ? WEXITSTATUS(raw) : -1, command + "\n" + output.str()};
}

std::string g17(double v) {
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.17g", v);
  return buf;
}

template <std::size_t N>
std::string csv_floats(const std::array<double, N>& values) {
  std::string out;
  for (const double v : values) out += "," + g17(v);
  return out;
}

std::string numbered(const std::string& prefix) {
  std::string out;
  for (int i = 0; i < 36; ++i) out += "," + prefix + std::to_string(i);
  return out;
}

void write_pose_csv(const fs::path& path, const std::vector<Pose>& poses) {
  std::ofstream out(path);
  out << "stamp_ns,frame_id,x,y,z,qx,qy,qz,qw" << numbered("cov") << '\n';
  for (const Pose& p : poses) {
    out << header_ns(p.sec, p.nanosec) << ',' << p.frame_id << csv_floats(p.pose) << csv_floats(p.cov)
        << '\n';
  }
}

void write_odometry_csv(const fs::path& path, const std::vector<Odometry>& odometry) {
  std::ofstream out(path);
  out << "stamp_ns,frame_id,child_frame_id,x,y,z,qx,qy,qz,qw,vx,vy,vz,wx,wy,wz" << numbered("pose_cov")
      << numbered("twist_cov") << '\n';
  for (const Odometry& o : odometry) {
    out << header_ns(o.sec, o.nanosec) << ',' << o.frame_id << ',' << o.child_frame_id << csv_floats(o.pose)
        << csv_floats(o.twist) << csv_floats(o.pose_cov) << csv_floats(o.twist_cov) << '\n';
  }
}

std::string error_of(const std::function<void()>& action) {
  try {
    action();
  } catch (const Rosbag2Error& e) {
    return e.what();
  } catch (const std::exception& e) {
    return std::string("not a Rosbag2Error: ") + e.what();
  }
  return "no exception";
}

bool contains(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

class Rosbag2 : public testing::Test {
 protected:
  void SetUp() override {
    const auto* info = testing::UnitTest::GetInstance()->current_test_info();
    root_ = fs::path(testing::TempDir()) /
            ("beaconloc_rosbag2_" + std::string(info->name()) + "_" + std::to_string(::getpid()));
    fs::remove_all(root_);
    fs::create_directories(root_);
  }
  void TearDown() override { fs::remove_all(root_); }

  fs::path root_;
};

// ---------------------------------------------------------------- a bag read back

TEST_F(Rosbag2, WrittenBagReadsBackWithSqliteAndYamlCpp) {
  const fs::path dir = root_ / "run";
  const ChosenValues values = chosen_values();
  const std::vector<Written> written = write_chosen_bag(dir, values);

  // Cleanly closed: the database alone (WAL folded back), and metadata.yaml; no temporary file.
  EXPECT_EQ(entries(dir), (std::set<std::string>{"metadata.yaml", "run_0.db3"}));
  Db db((dir / "run_0.db3").string());
  ASSERT_TRUE(db.ok()) << db.error();
  EXPECT_EQ(db.rows("PRAGMA journal_mode"), (Rows{{"delete"}}));
  EXPECT_EQ(db.rows("PRAGMA integrity_check"), (Rows{{"ok"}}));
  EXPECT_EQ(db.rows("SELECT schema_version, ros_distro FROM schema"), (Rows{{"3", "humble"}}));
  EXPECT_EQ(db.rows("SELECT name, type, \"notnull\", pk FROM pragma_table_info('messages') ORDER BY cid"),
            (Rows{{"id", "INTEGER", "0", "1"},
                  {"topic_id", "INTEGER", "1", "0"},
                  {"timestamp", "INTEGER", "1", "0"},
                  {"data", "BLOB", "1", "0"}}));
  EXPECT_EQ(db.rows("SELECT name, type, \"notnull\", pk FROM pragma_table_info('topics') ORDER BY cid"),
            (Rows{{"id", "INTEGER", "0", "1"},
                  {"name", "TEXT", "1", "0"},
                  {"type", "TEXT", "1", "0"},
                  {"serialization_format", "TEXT", "1", "0"},
                  {"offered_qos_profiles", "TEXT", "1", "0"}}));
  EXPECT_EQ(db.rows("SELECT name FROM pragma_index_info('timestamp_idx')"), (Rows{{"timestamp"}}));
  EXPECT_EQ(
      db.rows("SELECT id, name, type, serialization_format, offered_qos_profiles FROM topics ORDER BY id"),
      (Rows{{"1", "/beacon_pose", kPoseType, "cdr", expected_qos(1, 2, 10)},
            {"2", "/odom", kOdometryType, "cdr", expected_qos(2, 1, 5)}}));

  const Rows messages = db.rows("SELECT id, topic_id, timestamp, data FROM messages ORDER BY id");
  ASSERT_EQ(messages.size(), written.size());
  for (std::size_t i = 0; i < written.size(); ++i) {
    EXPECT_EQ(messages[i][0], std::to_string(i + 1));
    EXPECT_EQ(messages[i][1], std::to_string(written[i].topic_id));
    EXPECT_EQ(messages[i][2], std::to_string(written[i].received_ns));
    EXPECT_EQ(messages[i][3], text(written[i].data)) << "message " << i << " not byte-identical";
  }

  // Iron and Jazzy read the metadata table: one row, the BagMetadata mapping without a root key.
  const Rows metadata = db.rows("SELECT metadata_version, metadata FROM metadata");
  ASSERT_EQ(metadata.size(), 1u);
  EXPECT_EQ(metadata[0][0], "5");
  const YAML::Node row = YAML::Load(metadata[0][1]);
  EXPECT_EQ(row["version"].as<int>(), 5);
  EXPECT_EQ(row["message_count"].as<std::uint64_t>(), 5u);

  const YAML::Node info = bag_info(dir);
  const std::int64_t start = kT0 + 5'000'000;  // odometry 0, received first though written second
  const std::int64_t duration = kT0 + 2'500'000'000 - start;
  EXPECT_EQ(info["version"].as<int>(), 5);
  EXPECT_EQ(info["storage_identifier"].as<std::string>(), "sqlite3");
  EXPECT_EQ(info["message_count"].as<std::uint64_t>(), 5u);
  EXPECT_EQ(info["starting_time"]["nanoseconds_since_epoch"].as<std::int64_t>(), start);
  EXPECT_EQ(info["duration"]["nanoseconds"].as<std::int64_t>(), duration);
  EXPECT_EQ(info["compression_format"].as<std::string>(), "");
  EXPECT_EQ(info["compression_mode"].as<std::string>(), "");
  ASSERT_EQ(info["relative_file_paths"].size(), 1u);
  EXPECT_EQ(info["relative_file_paths"][0].as<std::string>(), "run_0.db3");
  ASSERT_EQ(info["files"].size(), 1u);
  EXPECT_EQ(info["files"][0]["path"].as<std::string>(), "run_0.db3");
  EXPECT_EQ(info["files"][0]["starting_time"]["nanoseconds_since_epoch"].as<std::int64_t>(), start);
  EXPECT_EQ(info["files"][0]["duration"]["nanoseconds"].as<std::int64_t>(), duration);
  EXPECT_EQ(info["files"][0]["message_count"].as<std::uint64_t>(), 5u);
  const YAML::Node topics = info["topics_with_message_count"];
  ASSERT_EQ(topics.size(), 2u);
  EXPECT_EQ(topics[0]["topic_metadata"]["name"].as<std::string>(), "/beacon_pose");
  EXPECT_EQ(topics[0]["topic_metadata"]["type"].as<std::string>(), kPoseType);
  EXPECT_EQ(topics[0]["topic_metadata"]["serialization_format"].as<std::string>(), "cdr");
  EXPECT_EQ(topics[0]["topic_metadata"]["offered_qos_profiles"].as<std::string>(), expected_qos(1, 2, 10));
  EXPECT_EQ(topics[0]["message_count"].as<std::uint64_t>(), 3u);
  EXPECT_EQ(topics[1]["topic_metadata"]["name"].as<std::string>(), "/odom");
  EXPECT_EQ(topics[1]["topic_metadata"]["type"].as<std::string>(), kOdometryType);
  EXPECT_EQ(topics[1]["topic_metadata"]["offered_qos_profiles"].as<std::string>(), expected_qos(2, 1, 5));
  EXPECT_EQ(topics[1]["message_count"].as<std::uint64_t>(), 2u);
  // The QoS string is itself YAML: what `ros2 bag play` publishes with.
  const YAML::Node qos = YAML::Load(topics[1]["topic_metadata"]["offered_qos_profiles"].as<std::string>());
  ASSERT_EQ(qos.size(), 1u);
  EXPECT_EQ(qos[0]["reliability"].as<int>(), 2);
  EXPECT_EQ(qos[0]["durability"].as<int>(), 1);
  EXPECT_EQ(qos[0]["depth"].as<int>(), 5);
  EXPECT_EQ(qos[0]["deadline"]["sec"].as<std::int64_t>(), 9223372036);
}

TEST_F(Rosbag2, IndependentReaderReadsTheWritersBag) {
  const fs::path dir = root_ / "run";
  ChosenValues values = chosen_values();
  write_chosen_bag(dir, values);
  const fs::path poses_csv = root_ / "poses.csv";
  const fs::path odometry_csv = root_ / "odometry.csv";
  write_pose_csv(poses_csv, values.poses);
  write_odometry_csv(odometry_csv, values.odometry);
  const std::string expectations =
      "--expect-poses '" + poses_csv.string() + "' --expect-odometry '" + odometry_csv.string() + "'";

  const CheckerRun passed = run_checker(dir, expectations + " --min-messages 5");
  EXPECT_EQ(passed.status, 0) << passed.output;
  EXPECT_TRUE(contains(passed.output, "/beacon_pose (" + std::string(kPoseType) + "): 3 messages, first " +
                                          std::to_string(kT0 + 10'000'000)))
      << passed.output;
  EXPECT_TRUE(contains(passed.output, "/odom (" + std::string(kOdometryType) + "): 2 messages"))
      << passed.output;

  // The reader compares: one expected value one ulp off fails it, naming the field.
  values.poses[1].cov[7] = std::nextafter(values.poses[1].cov[7], INFINITY);
  write_pose_csv(poses_csv, values.poses);
  const CheckerRun pose_off = run_checker(dir, expectations);
  EXPECT_EQ(pose_off.status, 1) << pose_off.output;
  EXPECT_TRUE(contains(pose_off.output, ": cov7 expected")) << pose_off.output;

  values = chosen_values();
  write_pose_csv(poses_csv, values.poses);
  values.odometry[1].twist[5] = std::nextafter(values.odometry[1].twist[5], -INFINITY);
  write_odometry_csv(odometry_csv, values.odometry);
  const CheckerRun odometry_off = run_checker(dir, expectations);
  EXPECT_EQ(odometry_off.status, 1) << odometry_off.output;
  EXPECT_TRUE(contains(odometry_off.output, ": wz expected")) << odometry_off.output;

  const CheckerRun too_few = run_checker(dir, "--min-messages 6");
  EXPECT_EQ(too_few.status, 1) << too_few.output;
}

// The reader is shown to fail on what it claims to check (each damage on a fresh copy of the bag).
TEST_F(Rosbag2, IndependentReaderRejectsADamagedBag) {
  struct Damage {
    const char* name;
    std::function<void(Db&, const std::vector<Written>&)> apply;
    const char* expected_output;
  };
  const std::vector<Damage> damages{
      {"truncated",
       [](Db& db, const std::vector<Written>& w) {
         db.set_message_data(1, Bytes(w[0].data.begin(), w[0].data.end() - 8));
       },
       "message id 1 (geometry_msgs/msg/PoseWithCovarianceStamped): truncated"},
      {"trailing bytes",
       [](Db& db, const std::vector<Written>& w) {
         Bytes longer = w[1].data;
         longer.insert(longer.end(), 8, 0);
         db.set_message_data(2, longer);
       },
       "message id 2 (nav_msgs/msg/Odometry): 8 bytes left"},
      {"big-endian header",
       [](Db& db, const std::vector<Written>& w) {
         Bytes other = w[2].data;
         other[1] = 0x00;
         db.set_message_data(3, other);
       },
       "message id 3: no CDR little-endian encapsulation header"},
      {"asymmetric covariance",
       [](Db& db, const std::vector<Written>&) {
         Pose p = chosen_values().poses[2];
         p.cov[1] += 1.0;
         db.set_message_data(5, cdr(p));
       },
       "message id 5 (geometry_msgs/msg/PoseWithCovarianceStamped): cov not symmetric at (0,1)"},
      {"not finite",
       [](Db& db, const std::vector<Written>&) {
         Odometry o = chosen_values().odometry[1];
         o.twist[0] = std::numeric_limits<double>::infinity();
         db.set_message_data(4, cdr(o));
       },
       "message id 4 (nav_msgs/msg/Odometry): vx is not finite"},
      {"message lost",
       [](Db& db, const std::vector<Written>&) {
         Rows rows;
         EXPECT_TRUE(db.query("DELETE FROM messages WHERE id = 4", rows)) << db.error();
       },
       "topic '/odom': metadata.yaml counts 2, the database holds 1"},
  };
  for (const Damage& damage : damages) {
    const fs::path dir = root_ / (std::string("bag_") + std::to_string(&damage - damages.data()));
    const std::vector<Written> written = write_chosen_bag(dir, chosen_values());
    ASSERT_EQ(run_checker(dir, "").status, 0) << damage.name;
    {
      Db db((dir / (dir.filename().string() + "_0.db3")).string(), SQLITE_OPEN_READWRITE);
      ASSERT_TRUE(db.ok()) << db.error();
      damage.apply(db, written);
    }
    const CheckerRun run = run_checker(dir, "");
    EXPECT_EQ(run.status, 1) << damage.name << "\n" << run.output;
    EXPECT_TRUE(contains(run.output, damage.expected_output)) << damage.name << "\n" << run.output;
  }
}

// ---------------------------------------------------------------- metadata.yaml while recording

TEST_F(Rosbag2, MetadataRewrittenAtMostOncePerSecondOfStamps) {
  const fs::path dir = root_ / "live";
  Rosbag2Writer writer(dir.string());
  EXPECT_EQ(writer.database_path(), (dir / "live_0.db3").string());
  // Opened: a valid metadata.yaml, no message, no topic.
  EXPECT_EQ(bag_info(dir)["message_count"].as<std::uint64_t>(), 0u);
  EXPECT_EQ(bag_info(dir)["topics_with_message_count"].size(), 0u);
  EXPECT_EQ(bag_info(dir)["starting_time"]["nanoseconds_since_epoch"].as<std::int64_t>(), 0);

  const int topic = writer.add_topic("/beacon_pose", kPoseType, TopicQos{});
  ASSERT_EQ(bag_info(dir)["topics_with_message_count"].size(), 1u);  // listed before any message

  const Bytes message = cdr(chosen_values().poses[0]);
  const auto write_at = [&](std::int64_t stamp) {
    writer.write(topic, stamp, message.data(), message.size());
  };
  const auto counted = [&] { return bag_info(dir)["message_count"].as<std::uint64_t>(); };
  write_at(kT0);
  EXPECT_EQ(counted(), 1u);  // the first message since the opening
  write_at(kT0 + 500'000'000);
  EXPECT_EQ(counted(), 1u);
  write_at(kT0 + 999'999'999);
  EXPECT_EQ(counted(), 1u);
  write_at(kT0 - 3'000'000'000);  // an older stamp is no second later
  EXPECT_EQ(counted(), 1u);
  write_at(kT0 + 1'000'000'000);
  EXPECT_EQ(counted(), 5u);
  EXPECT_EQ(bag_info(dir)["starting_time"]["nanoseconds_since_epoch"].as<std::int64_t>(),
            kT0 - 3'000'000'000);
  EXPECT_EQ(bag_info(dir)["duration"]["nanoseconds"].as<std::int64_t>(), 4'000'000'000);
  write_at(kT0 + 1'900'000'000);
  EXPECT_EQ(counted(), 5u);
  write_at(kT0 + 2'000'000'000);
  EXPECT_EQ(counted(), 7u);
  write_at(kT0 + 2'100'000'000);
  EXPECT_EQ(counted(), 7u);
  EXPECT_EQ(writer.message_count(), 8u);
  // While recording the database stays in WAL mode, readable from another connection.
  EXPECT_EQ(message_rows(writer.database_path()), 8);
  writer.close();
  EXPECT_EQ(counted(), 8u);
  EXPECT_EQ(entries(dir), (std::set<std::string>{"metadata.yaml", "live_0.db3"}));
}

// ---------------------------------------------------------------- a kill mid-writing

std::int64_t kill_stamp(std::uint64_t i) { return kT0 + static_cast<std::int64_t>(i) * 10'000'000; }

Bytes kill_message(std::uint64_t i) {
  const auto k = static_cast<double>(i);
  return cdr(Pose{1'700'000'000 + static_cast<std::int32_t>(i / 100),
                  static_cast<std::uint32_t>(i % 100) * 10'000'000u, "map", pose_values(k),
                  covariance(1.0 + k), kill_stamp(i)});
}

TEST_F(Rosbag2, KillMidWritingLeavesEveryWrittenMessageWhole) {
  constexpr std::int64_t kAtLeast = 3000;  // 30 s of stamps: about 30 metadata.yaml rewrites
  const fs::path dir = root_ / "killed";
  const fs::path db_path = dir / "killed_0.db3";
  // How many write() calls have returned in the child, shared with this process.
  void* shared = ::mmap(nullptr, sizeof(std::atomic<std::uint64_t>), PROT_READ | PROT_WRITE,
                        MAP_SHARED | MAP_ANONYMOUS, -1, 0);
  ASSERT_NE(shared, MAP_FAILED);
  auto* returned = new (shared) std::atomic<std::uint64_t>(0);
  static_assert(std::atomic<std::uint64_t>::is_always_lock_free, "shared between processes");
  std::fflush(nullptr);  // nothing buffered twice
  const pid_t child = ::fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    // The recorder: writes until killed, never closes. _exit keeps it out of gtest's teardown.
    try {
      Rosbag2Writer writer(dir.string());
      const int topic = writer.add_topic("/beacon_pose", kPoseType, TopicQos{});
      for (std::uint64_t i = 0;; ++i) {
        const Bytes m = kill_message(i);
        writer.write(topic, kill_stamp(i), m.data(), m.size());
        returned->store(i + 1);
      }
    } catch (...) {
      ::_exit(3);
    }
  }

  std::int64_t seen = 0;
  int status = 0;
  bool exited = false;
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
  while (seen < kAtLeast && std::chrono::steady_clock::now() < deadline) {
    if (::waitpid(child, &status, WNOHANG) == child) {
      exited = true;
      break;
    }
    seen = message_rows(db_path);  // read-only, while the child writes
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  if (!exited) {
    ::kill(child, SIGKILL);
    ASSERT_EQ(::waitpid(child, &status, 0), child);
  }
  ASSERT_TRUE(WIFSIGNALED(status) && WTERMSIG(status) == SIGKILL)
      << "the recorder was not killed mid-writing";
  ASSERT_GE(seen, kAtLeast);
  const std::uint64_t returned_before_kill = returned->load();
  ::munmap(shared, sizeof(std::atomic<std::uint64_t>));

  Db db(db_path.string());
  ASSERT_TRUE(db.ok()) << db.error();
  EXPECT_EQ(db.rows("PRAGMA integrity_check"), (Rows{{"ok"}}));
  const Rows rows = db.rows("SELECT id, topic_id, timestamp, data FROM messages ORDER BY id");
  ASSERT_GE(static_cast<std::int64_t>(rows.size()), seen);
  // Every message whose write() returned is there; one more when the kill came between the
  // commit and the child's count.
  EXPECT_GE(rows.size(), returned_before_kill);
  EXPECT_LE(rows.size(), returned_before_kill + 1);
  for (std::size_t i = 0; i < rows.size(); ++i) {
    ASSERT_EQ(rows[i][0], std::to_string(i + 1)) << "ids not contiguous from 1";
    ASSERT_EQ(rows[i][1], "1");
    ASSERT_EQ(rows[i][2], std::to_string(kill_stamp(i)));
    ASSERT_EQ(rows[i][3], text(kill_message(i))) << "message " << i << " not whole";
  }
  const YAML::Node info = bag_info(dir);
  const auto counted = info["message_count"].as<std::uint64_t>();
  EXPECT_GT(counted, 0u);
  EXPECT_LE(counted, rows.size());
  EXPECT_EQ(info["topics_with_message_count"][0]["message_count"].as<std::uint64_t>(), counted);

  const CheckerRun run = run_checker(dir, "--after-kill --min-messages " + std::to_string(kAtLeast));
  EXPECT_EQ(run.status, 0) << run.output;
  // Without --after-kill the reader insists on a cleanly closed bag (the metadata row is written at close).
  const CheckerRun strict = run_checker(dir, "");
  EXPECT_EQ(strict.status, 1) << strict.output;
  EXPECT_TRUE(contains(strict.output, "metadata table holds 0 rows")) << strict.output;
}

// ---------------------------------------------------------------- concurrency

TEST_F(Rosbag2, ConcurrentWritersLoseNothing) {
  const fs::path dir = root_ / "threads";
  Rosbag2Writer writer(dir.string());
  constexpr int kThreads = 4;
  constexpr int kEach = 250;
  std::vector<int> topics;
  for (int t = 0; t < kThreads; ++t)
    topics.push_back(writer.add_topic("/t" + std::to_string(t), kPoseType, {}));
  std::vector<std::thread> threads;
  for (int t = 0; t < kThreads; ++t) {
    threads.emplace_back([&, t] {
      for (int i = 0; i < kEach; ++i) {
        const Bytes m = kill_message(static_cast<std::uint64_t>(t * kEach + i));
        writer.write(topics[static_cast<std::size_t>(t)], kT0 + i, m.data(), m.size());
      }
    });
  }
  for (std::thread& t : threads) t.join();
  writer.close();
  EXPECT_EQ(message_rows(writer.database_path()), kThreads * kEach);
  Db db(writer.database_path());
  EXPECT_EQ(db.rows("SELECT COUNT(*), MIN(id), MAX(id) FROM messages"),
            (Rows{{std::to_string(kThreads * kEach), "1", std::to_string(kThreads * kEach)}}));
  const YAML::Node info = bag_info(dir);
  for (int t = 0; t < kThreads; ++t) {
    EXPECT_EQ(info["topics_with_message_count"][t]["message_count"].as<int>(), kEach);
  }
}

// ---------------------------------------------------------------- refusals

TEST_F(Rosbag2, RefusesADirectoryThatIsNotEmpty) {
  const fs::path full = root_ / "full";
  fs::create_directories(full);
  std::ofstream(full / "other.txt") << "someone else's\n";
  const std::string error = error_of([&] { Rosbag2Writer writer(full.string()); });
  EXPECT_TRUE(contains(error, "'" + full.string() + "'")) << error;
  EXPECT_TRUE(contains(error, "exists and is not empty")) << error;
  EXPECT_EQ(entries(full), (std::set<std::string>{"other.txt"}));  // untouched

  const fs::path file = root_ / "file";
  std::ofstream(file) << "x\n";
  const std::string not_directory = error_of([&] { Rosbag2Writer writer(file.string()); });
  EXPECT_TRUE(contains(not_directory, "'" + file.string() + "': exists and is not a directory"))
      << not_directory;

  // An empty directory is taken; a trailing slash does not change the database's name.
  const fs::path empty = root_ / "empty";
  fs::create_directories(empty);
  Rosbag2Writer writer(empty.string() + "/");
  EXPECT_EQ(fs::path(writer.database_path()).filename().string(), "empty_0.db3");
  writer.close();
  EXPECT_EQ(entries(empty), (std::set<std::string>{"metadata.yaml", "empty_0.db3"}));
}

// Each refused message leaves no row, and the bag stays valid for the reader.
class Rosbag2Refusals : public Rosbag2 {
 protected:
  void SetUp() override {
    Rosbag2::SetUp();
    writer_ = std::make_unique<Rosbag2Writer>((root_ / "bag").string());
    topic_ = writer_->add_topic("/beacon_pose", kPoseType, TopicQos{});
  }
  void expect_nothing_written() {
    EXPECT_EQ(writer_->message_count(), 0u);
    writer_->close();
    EXPECT_EQ(message_rows(root_ / "bag" / "bag_0.db3"), 0);
    EXPECT_EQ(bag_info(root_ / "bag")["message_count"].as<std::uint64_t>(), 0u);
    const CheckerRun run = run_checker(root_ / "bag", "");
    EXPECT_EQ(run.status, 0) << run.output;
  }

  std::unique_ptr<Rosbag2Writer> writer_;
  int topic_ = 0;
  const Bytes message_ = cdr(chosen_values().poses[0]);
};

TEST_F(Rosbag2Refusals, UnknownTopicId) {
  const std::string error =
      error_of([&] { writer_->write(topic_ + 41, kT0, message_.data(), message_.size()); });
  EXPECT_TRUE(contains(error, "unknown topic id " + std::to_string(topic_ + 41))) << error;
  expect_nothing_written();
}

TEST_F(Rosbag2Refusals, DuplicateTopic) {
  const std::string error = error_of([&] { writer_->add_topic("/beacon_pose", kOdometryType, TopicQos{}); });
  EXPECT_TRUE(contains(error, "topic '/beacon_pose' is already in the bag (id 1)")) << error;
  EXPECT_EQ(Db((root_ / "bag" / "bag_0.db3").string()).rows("SELECT COUNT(*) FROM topics"), (Rows{{"1"}}));
  expect_nothing_written();
}

TEST_F(Rosbag2Refusals, BadTopicName) {
  EXPECT_TRUE(contains(error_of([&] { writer_->add_topic("", kPoseType, {}); }), "empty topic name"));
  const std::string relative = error_of([&] { writer_->add_topic("beacon_pose", kPoseType, {}); });
  EXPECT_TRUE(contains(relative, "topic name 'beacon_pose' does not start with '/'")) << relative;
  const std::string spaced = error_of([&] { writer_->add_topic("/beacon pose", kPoseType, {}); });
  EXPECT_TRUE(contains(spaced, "'/beacon pose' holds a space or a control character")) << spaced;
  const std::string untyped = error_of([&] { writer_->add_topic("/odom", "", {}); });
  EXPECT_TRUE(contains(untyped, "topic '/odom' has an empty type")) << untyped;
  EXPECT_EQ(Db((root_ / "bag" / "bag_0.db3").string()).rows("SELECT COUNT(*) FROM topics"), (Rows{{"1"}}));
  expect_nothing_written();
}

TEST_F(Rosbag2Refusals, NegativeStamp) {
  const std::string error = error_of([&] { writer_->write(topic_, -1, message_.data(), message_.size()); });
  EXPECT_TRUE(contains(error, "negative stamp -1 ns on topic '/beacon_pose'")) << error;
  expect_nothing_written();
}

TEST_F(Rosbag2Refusals, MessageShorterThanItsEncapsulationHeader) {
  for (const std::size_t size : {std::size_t{0}, std::size_t{3}}) {
    const std::string error = error_of([&] { writer_->write(topic_, kT0, message_.data(), size); });
    EXPECT_TRUE(
        contains(error, "message of " + std::to_string(size) +
                            " bytes on topic '/beacon_pose' is shorter than the 4-byte CDR encapsulation"))
        << error;
  }
  const std::string null = error_of([&] { writer_->write(topic_, kT0, nullptr, 100); });
  EXPECT_TRUE(contains(null, "message of 0 bytes")) << null;
  expect_nothing_written();
}

TEST_F(Rosbag2Refusals, EverythingAfterClose) {
  writer_->close();
  writer_->close();  // again: nothing
  const std::string write = error_of([&] { writer_->write(topic_, kT0, message_.data(), message_.size()); });
  EXPECT_TRUE(contains(write, "write after close()")) << write;
  const std::string add = error_of([&] { writer_->add_topic("/odom", kOdometryType, {}); });
  EXPECT_TRUE(contains(add, "add_topic after close()")) << add;
  expect_nothing_written();
}

}  // namespace
}  // namespace beaconloc::rosbag2
