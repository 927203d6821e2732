#pragma once
// A rosbag2 bag (sqlite3 storage) written from serialized messages, without ROS 2 and without DDS,
// laid out as Humble writes it (database schema 3, metadata.yaml version 5) so that `ros2 bag info`
// and `ros2 bag play` open it on Humble, Iron and Jazzy:
//   DIR/<basename(DIR)>_0.db3   tables schema, metadata, topics, messages (index timestamp_idx)
//   DIR/metadata.yaml           rosbag2_bagfile_information
// Crash safety: each message is its own sqlite transaction in WAL mode, so after a kill of the
// writing process the database opens and holds, whole, every message whose write() returned.
// metadata.yaml is replaced atomically (rename) and never counts a message the database lacks.
#include <cstddef>
#include <cstdint>
#include <map>
#include <memory>
#include <mutex>
#include <stdexcept>
#include <string>

struct sqlite3;
struct sqlite3_stmt;

namespace beaconloc::rosbag2 {

// The QoS the topic's publishers offered, kept in the bag for `ros2 bag play` to publish with.
struct TopicQos {
  bool reliable = true;          // else best effort
  bool transient_local = false;  // else volatile
  std::uint32_t depth = 10;      // keep last
};

// Every refusal and every storage failure (its message names the file and sqlite's or the OS's error).
class Rosbag2Error : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

class Rosbag2Writer {
 public:
  // directory must not exist yet, or be an empty directory. ros_distro goes into the schema table.
  explicit Rosbag2Writer(const std::string& directory, const std::string& ros_distro = "humble");
  ~Rosbag2Writer();  // close(), never throws
  Rosbag2Writer(const Rosbag2Writer&) = delete;
  Rosbag2Writer& operator=(const Rosbag2Writer&) = delete;

  // Registers a topic (name "/beacon_pose", type "geometry_msgs/msg/PoseWithCovarianceStamped",
  // serialization format cdr); returns its id. Refused: an empty name or one not starting with '/',
  // a space or control character in it, a name already registered, an empty type.
  int add_topic(const std::string& name, const std::string& type, TopicQos qos);
  // One serialized message (CDR with its 4-byte encapsulation header), stamped when received, in ns
  // since the epoch; committed to the database before it returns. Refused, nothing written: an
  // unknown topic id, a negative stamp, fewer than 4 bytes. A storage failure throws too (after
  // the commit when only the metadata.yaml rewrite failed: the message is in the database).
  void write(int topic_id, std::int64_t stamp_ns, const std::uint8_t* data, std::size_t size);
  // Final metadata (database and metadata.yaml), the WAL folded back: a closed bag is one .db3 file.
  // Closes even when a step fails (then throws the first failure). Further calls do nothing;
  // add_topic() and write() refuse after it.
  void close();

  std::uint64_t message_count() const;
  std::string database_path() const;

 private:
  struct Topic {
    std::string name;
    std::string type;
    std::string qos_profiles;  // offered_qos_profiles, the YAML string
    std::uint64_t messages = 0;
  };
  struct DbClose {
    void operator()(sqlite3* db) const;
  };
  struct StmtFinalize {
    void operator()(sqlite3_stmt* stmt) const;
  };
  using Statement = std::unique_ptr<sqlite3_stmt, StmtFinalize>;

  void open_database(const std::string& ros_distro);
  Statement prepare(const char* sql);
  void exec(const char* sql);
  std::string query_text(const char* sql);  // the first column of the first row, "" when none
  std::string error_text(const std::string& what) const;
  [[noreturn]] void fail(const std::string& what) const;
  void require_open(const char* operation) const;
  std::string metadata_body() const;
  void write_metadata_file() const;
  void close_locked();

  mutable std::mutex mutex_;
  std::string directory_;
  std::string database_file_;  // <basename(DIR)>_0.db3, relative to the directory
  std::string database_path_;
  std::unique_ptr<sqlite3, DbClose> db_;
  Statement insert_message_;
  std::map<int, Topic> topics_;  // by id, the topics table's row id
  std::uint64_t messages_ = 0;
  std::int64_t oldest_stamp_ns_ = 0;  // of the messages written, valid when messages_ > 0
  std::int64_t newest_stamp_ns_ = 0;
  // metadata.yaml's last rewrite from write(): at most one per second of message stamps.
  std::uint64_t messages_at_rewrite_ = 0;
  std::int64_t newest_at_rewrite_ns_ = 0;
};

}  // namespace beaconloc::rosbag2
