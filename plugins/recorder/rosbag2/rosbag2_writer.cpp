#include "rosbag2_writer.hpp"

#include <sqlite3.h>

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <sstream>
#include <system_error>

#include "beaconloc/core/time.hpp"

namespace beaconloc::rosbag2 {
namespace {

namespace fs = std::filesystem;

// Humble's sqlite3 storage writes schema version 3 (rosbag2_storage_default_plugins, sqlite_storage.hpp);
// Iron and Jazzy read it (they write 4, which adds a message_definitions table Humble does not know).
constexpr int kSchemaVersion = 3;
// Humble's BagMetadata version. Iron and Jazzy read it; they read the topics' offered_qos_profiles
// as the YAML string of versions <= 8 (with integer enums).
constexpr int kMetadataVersion = 5;
// What Humble records for a duration a publisher leaves unset (RMW_DURATION_INFINITE, as
// rosbag2's own test bags hold it).
constexpr const char* kInfiniteDuration = "\n    sec: 9223372036\n    nsec: 854775807";

std::string in_bag(const std::string& directory, const std::string& what) {
  return "rosbag2 bag '" + directory + "': " + what;
}

// A YAML double-quoted scalar: any string (names, types, the QoS text with its newlines) reads back
// exactly, whatever it holds.
std::string yaml_quoted(const std::string& text) {
  std::string out = "\"";
  for (const char c : text) {
    const auto byte = static_cast<unsigned char>(c);
    if (c == '"' || c == '\\') {
      out += '\\';
      out += c;
    } else if (c == '\n') {
      out += "\\n";
    } else if (byte < 0x20 || byte == 0x7f) {
      char escaped[8];
      std::snprintf(escaped, sizeof escaped, "\\x%02x", byte);
      out += escaped;
    } else {
      out += c;
    }
  }
  return out + '"';
}

std::string indented(const std::string& text, const std::string& indent) {
  std::string out;
  std::size_t begin = 0;
  while (begin < text.size()) {
    const std::size_t end = text.find('\n', begin);
    const std::size_t stop = end == std::string::npos ? text.size() : end + 1;
    out += indent + text.substr(begin, stop - begin);
    begin = stop;
  }
  return out;
}

// offered_qos_profiles: one profile, the form Humble writes (integer enums: history 1 keep last;
// reliability 1 reliable, 2 best effort; durability 1 transient local, 2 volatile; liveliness 1
// automatic).
std::string qos_profiles_yaml(const TopicQos& qos) {
  std::ostringstream y;
  y << "- history: 1\n  depth: " << qos.depth << "\n  reliability: " << (qos.reliable ? 1 : 2)
    << "\n  durability: " << (qos.transient_local ? 1 : 2) << "\n  deadline:" << kInfiniteDuration
    << "\n  lifespan:" << kInfiniteDuration
    << "\n  liveliness: 1\n  liveliness_lease_duration:" << kInfiniteDuration
    << "\n  avoid_ros_namespace_conventions: false";
  return y.str();
}

// The database is named after the directory's last component, as rosbag2 names it: "bags/run/"
// and "bags/run/." give run_0.db3.
std::string database_file_name(const std::string& directory) {
  std::error_code ec;
  fs::path path = fs::absolute(directory, ec).lexically_normal();
  if (ec) throw Rosbag2Error(in_bag(directory, "cannot resolve the path: " + ec.message()));
  if (!path.has_filename()) path = path.parent_path();
  const std::string base = path.filename().string();
  if (base.empty() || base == "." || base == "..") {
    throw Rosbag2Error(in_bag(directory, "the directory needs a name (its database is <name>_0.db3)"));
  }
  return base + "_0.db3";
}

// A bag is never written over or next to another: the directory is new, or empty.
void prepare_directory(const std::string& directory) {
  if (directory.empty()) throw Rosbag2Error("rosbag2 bag: empty directory name");
  std::error_code ec;
  const bool exists = fs::exists(directory, ec);
  if (ec) throw Rosbag2Error(in_bag(directory, "cannot inspect: " + ec.message()));
  if (!exists) {
    fs::create_directories(directory, ec);
    if (ec) throw Rosbag2Error(in_bag(directory, "cannot create the directory: " + ec.message()));
    return;
  }
  if (!fs::is_directory(directory, ec)) {
    throw Rosbag2Error(in_bag(directory, "exists and is not a directory"));
  }
  const bool empty = fs::is_empty(directory, ec);
  if (ec) throw Rosbag2Error(in_bag(directory, "cannot list the directory: " + ec.message()));
  if (!empty) throw Rosbag2Error(in_bag(directory, "the directory exists and is not empty"));
}

void check_topic_name(const std::string& directory, const std::string& name) {
  if (name.empty()) throw Rosbag2Error(in_bag(directory, "empty topic name"));
  if (name.front() != '/') {
    throw Rosbag2Error(in_bag(directory, "topic name '" + name + "' does not start with '/'"));
  }
  for (const char c : name) {
    const auto byte = static_cast<unsigned char>(c);
    if (byte <= 0x20 || byte == 0x7f) {
      throw Rosbag2Error(in_bag(directory, "topic name '" + name + "' holds a space or a control character"));
    }
  }
}

}  // namespace

void Rosbag2Writer::DbClose::operator()(sqlite3* db) const { sqlite3_close_v2(db); }
void Rosbag2Writer::StmtFinalize::operator()(sqlite3_stmt* stmt) const { sqlite3_finalize(stmt); }

Rosbag2Writer::Rosbag2Writer(const std::string& directory, const std::string& ros_distro)
    : directory_(directory) {
  if (ros_distro.empty()) throw Rosbag2Error(in_bag(directory, "empty ros_distro"));
  database_file_ = database_file_name(directory);
  prepare_directory(directory);
  database_path_ = (fs::path(directory) / database_file_).string();
  open_database(ros_distro);
  // A bag with no message yet still opens in `ros2 bag info`, and a kill before the first
  // rewrite leaves a valid metadata.yaml.
  write_metadata_file();
}

Rosbag2Writer::~Rosbag2Writer() {
  try {
    close();
  } catch (const std::exception& e) {
    // A destructor must not throw: what was committed stays in the database.
    std::fprintf(stderr, "beaconloc rosbag2: closing failed: %s\n", e.what());
  } catch (...) {
    std::fprintf(stderr, "beaconloc rosbag2: closing %s failed\n", database_path_.c_str());
  }
}

void Rosbag2Writer::open_database(const std::string& ros_distro) {
  sqlite3* raw = nullptr;
  const int rc =
      sqlite3_open_v2(database_path_.c_str(), &raw, SQLITE_OPEN_READWRITE | SQLITE_OPEN_CREATE, nullptr);
  db_.reset(raw);  // closed by db_ even when the open failed
  if (rc != SQLITE_OK) {
    throw Rosbag2Error(database_path_ + ": cannot create the database: " +
                       (raw != nullptr ? sqlite3_errmsg(raw) : sqlite3_errstr(rc)));
  }
  if (sqlite3_extended_result_codes(db_.get(), 1) != SQLITE_OK) fail("cannot enable extended result codes");
  // A reader (a monitor, `ros2 bag info` on the database) may hold a lock for a moment: wait for it
  // rather than lose the message.
  if (sqlite3_busy_timeout(db_.get(), 5000) != SQLITE_OK) fail("cannot set the busy timeout");
  // WAL with one transaction per message: after a kill of this process the database holds every
  // committed message, whole (synchronous=NORMAL risks only the last commits on a power loss).
  const std::string mode = query_text("PRAGMA journal_mode=WAL");
  if (mode != "wal") fail("journal_mode stays '" + mode + "', not wal");
  exec("PRAGMA synchronous=NORMAL");

  // All tables or none: a kill while creating them leaves no half-made bag.
  exec("BEGIN");
  exec("CREATE TABLE schema(schema_version INTEGER PRIMARY KEY, ros_distro TEXT NOT NULL)");
  exec(
      "CREATE TABLE metadata(id INTEGER PRIMARY KEY, metadata_version INTEGER NOT NULL, "
      "metadata TEXT NOT NULL)");
  exec(
      "CREATE TABLE topics(id INTEGER PRIMARY KEY, name TEXT NOT NULL, type TEXT NOT NULL, "
      "serialization_format TEXT NOT NULL, offered_qos_profiles TEXT NOT NULL)");
  exec(
      "CREATE TABLE messages(id INTEGER PRIMARY KEY, topic_id INTEGER NOT NULL, timestamp INTEGER NOT NULL, "
      "data BLOB NOT NULL)");
  exec("CREATE INDEX timestamp_idx ON messages (timestamp ASC)");
  {
    const Statement schema = prepare("INSERT INTO schema (schema_version, ros_distro) VALUES (?, ?)");
    if (sqlite3_bind_int(schema.get(), 1, kSchemaVersion) != SQLITE_OK ||
        sqlite3_bind_text(schema.get(), 2, ros_distro.c_str(), static_cast<int>(ros_distro.size()),
                          SQLITE_TRANSIENT) != SQLITE_OK) {
      fail("cannot bind the schema row");
    }
    if (sqlite3_step(schema.get()) != SQLITE_DONE) fail("cannot insert the schema row");
  }
  exec("COMMIT");

  insert_message_ = prepare("INSERT INTO messages (timestamp, topic_id, data) VALUES (?, ?, ?)");
}

int Rosbag2Writer::add_topic(const std::string& name, const std::string& type, TopicQos qos) {
  const std::lock_guard<std::mutex> lock(mutex_);
  require_open("add_topic");
  check_topic_name(directory_, name);
  if (type.empty()) throw Rosbag2Error(in_bag(directory_, "topic '" + name + "' has an empty type"));
  for (const auto& [id, topic] : topics_) {
    if (topic.name == name) {
      throw Rosbag2Error(
          in_bag(directory_, "topic '" + name + "' is already in the bag (id " + std::to_string(id) + ")"));
    }
  }
  Topic topic{name, type, qos_profiles_yaml(qos)};
  const Statement insert = prepare(
      "INSERT INTO topics (name, type, serialization_format, offered_qos_profiles) VALUES (?, ?, 'cdr', ?)");
  const auto bind_text = [&](int index, const std::string& text) {
    return sqlite3_bind_text(insert.get(), index, text.c_str(), static_cast<int>(text.size()),
                             SQLITE_TRANSIENT) == SQLITE_OK;
  };
  if (!bind_text(1, topic.name) || !bind_text(2, topic.type) || !bind_text(3, topic.qos_profiles)) {
    fail("cannot bind topic '" + name + "'");
  }
  if (sqlite3_step(insert.get()) != SQLITE_DONE) fail("cannot insert topic '" + name + "'");
  const auto id = static_cast<int>(sqlite3_last_insert_rowid(db_.get()));
  topics_.emplace(id, std::move(topic));
  // A kill before the next rewrite still leaves the topic listed: rosbag2's reader plays nothing
  // of a bag whose metadata.yaml lists no topic.
  write_metadata_file();
  return id;
}

void Rosbag2Writer::write(int topic_id, std::int64_t stamp_ns, const std::uint8_t* data, std::size_t size) {
  const std::lock_guard<std::mutex> lock(mutex_);
  require_open("write");
  const auto found = topics_.find(topic_id);
  if (found == topics_.end()) {
    throw Rosbag2Error(in_bag(directory_, "unknown topic id " + std::to_string(topic_id)));
  }
  Topic& topic = found->second;
  if (stamp_ns < 0) {
    throw Rosbag2Error(in_bag(
        directory_, "negative stamp " + std::to_string(stamp_ns) + " ns on topic '" + topic.name + "'"));
  }
  if (data == nullptr || size < 4) {
    throw Rosbag2Error(in_bag(directory_, "message of " + std::to_string(data == nullptr ? 0 : size) +
                                              " bytes on topic '" + topic.name +
                                              "' is shorter than the 4-byte CDR encapsulation header"));
  }

  sqlite3_stmt* insert = insert_message_.get();
  // SQLITE_STATIC: sqlite reads the bytes during the step, while the caller still holds them.
  if (sqlite3_bind_int64(insert, 1, stamp_ns) != SQLITE_OK ||
      sqlite3_bind_int(insert, 2, topic_id) != SQLITE_OK ||
      sqlite3_bind_blob64(insert, 3, data, static_cast<sqlite3_uint64>(size), SQLITE_STATIC) != SQLITE_OK) {
    const std::string error = error_text("cannot bind a message on topic '" + topic.name + "'");
    sqlite3_clear_bindings(insert);
    throw Rosbag2Error(error);
  }
  const int rc = sqlite3_step(insert);
  // The error text first: reset() may replace it.
  const std::string error =
      rc == SQLITE_DONE ? std::string() : error_text("cannot insert a message on topic '" + topic.name + "'");
  sqlite3_reset(insert);
  sqlite3_clear_bindings(insert);
  if (rc != SQLITE_DONE) throw Rosbag2Error(error);

  ++topic.messages;
  ++messages_;
  oldest_stamp_ns_ = messages_ == 1 ? stamp_ns : std::min(oldest_stamp_ns_, stamp_ns);
  newest_stamp_ns_ = messages_ == 1 ? stamp_ns : std::max(newest_stamp_ns_, stamp_ns);
  // The writer reads no clock: a second of message stamps since the last rewrite's newest one.
  // (Both stamps are >= 0: the difference cannot overflow.)
  if (messages_at_rewrite_ == 0 || stamp_ns - newest_at_rewrite_ns_ >= kNsPerSecond) {
    write_metadata_file();
    messages_at_rewrite_ = messages_;
    newest_at_rewrite_ns_ = newest_stamp_ns_;
  }
}

void Rosbag2Writer::close() {
  const std::lock_guard<std::mutex> lock(mutex_);
  close_locked();
}

void Rosbag2Writer::close_locked() {
  if (!db_) return;
  std::string error;
  try {
    // Iron and Jazzy read the newest row of this table (the BagMetadata mapping, no root key).
    const std::string body = metadata_body();
    const Statement insert = prepare("INSERT INTO metadata (metadata_version, metadata) VALUES (?, ?)");
    if (sqlite3_bind_int(insert.get(), 1, kMetadataVersion) != SQLITE_OK ||
        sqlite3_bind_text(insert.get(), 2, body.c_str(), static_cast<int>(body.size()), SQLITE_TRANSIENT) !=
            SQLITE_OK) {
      fail("cannot bind the metadata row");
    }
    if (sqlite3_step(insert.get()) != SQLITE_DONE) fail("cannot insert the metadata row");
    // The WAL folded into the database, then back to a rollback journal: a cleanly closed bag is
    // the one .db3 file that metadata.yaml lists, whole when copied alone.
    const std::string busy = query_text("PRAGMA wal_checkpoint(TRUNCATE)");
    if (busy != "0") fail("cannot checkpoint the WAL (a reader holds it)");
    const std::string mode = query_text("PRAGMA journal_mode=DELETE");
    if (mode != "delete") fail("journal_mode stays '" + mode + "', not delete");
  } catch (const Rosbag2Error& e) {
    error = e.what();
  }
  insert_message_.reset();
  const int rc = sqlite3_close(db_.get());
  if (rc == SQLITE_OK) {
    db_.release();  // closed
  } else if (error.empty()) {
    error = database_path_ + ": cannot close the database: " + sqlite3_errstr(rc);
  }
  db_.reset();  // after a failed close: sqlite3_close_v2 frees it once its statements are gone
  try {
    write_metadata_file();
  } catch (const Rosbag2Error& e) {
    if (error.empty()) error = e.what();
  }
  if (!error.empty()) throw Rosbag2Error(error);
}

std::uint64_t Rosbag2Writer::message_count() const {
  const std::lock_guard<std::mutex> lock(mutex_);
  return messages_;
}

std::string Rosbag2Writer::database_path() const { return database_path_; }

// The BagMetadata mapping as rosbag2's yaml-cpp encoder lays it out (version 5 fields). With no
// message, starting time and duration are 0, as the sqlite3 storage reports an empty bag.
std::string Rosbag2Writer::metadata_body() const {
  const std::int64_t start = messages_ > 0 ? oldest_stamp_ns_ : 0;
  const std::int64_t duration = messages_ > 0 ? newest_stamp_ns_ - oldest_stamp_ns_ : 0;
  std::ostringstream y;
  y << "version: " << kMetadataVersion
    << "\nstorage_identifier: sqlite3\nduration:\n  nanoseconds: " << duration
    << "\nstarting_time:\n  nanoseconds_since_epoch: " << start << "\nmessage_count: " << messages_ << '\n';
  y << "topics_with_message_count:" << (topics_.empty() ? " []\n" : "\n");
  for (const auto& [id, topic] : topics_) {
    y << "  - topic_metadata:\n      name: " << yaml_quoted(topic.name)
      << "\n      type: " << yaml_quoted(topic.type)
      << "\n      serialization_format: cdr\n      offered_qos_profiles: " << yaml_quoted(topic.qos_profiles)
      << "\n    message_count: " << topic.messages << '\n';
  }
  y << "compression_format: \"\"\ncompression_mode: \"\"\nrelative_file_paths:\n  - "
    << yaml_quoted(database_file_) << "\nfiles:\n  - path: " << yaml_quoted(database_file_)
    << "\n    starting_time:\n      nanoseconds_since_epoch: " << start
    << "\n    duration:\n      nanoseconds: " << duration << "\n    message_count: " << messages_ << '\n';
  return y.str();
}

// Written to a temporary file in the bag directory and renamed over metadata.yaml: a kill at any
// moment leaves the previous or the new file, each whole (fsync is not needed for a process kill).
void Rosbag2Writer::write_metadata_file() const {
  const std::string text = "rosbag2_bagfile_information:\n" + indented(metadata_body(), "  ");
  const std::string path = (fs::path(directory_) / "metadata.yaml").string();
  const std::string temporary = (fs::path(directory_) / ".metadata.yaml.tmp").string();
  std::FILE* file = std::fopen(temporary.c_str(), "wb");
  if (file == nullptr) throw Rosbag2Error(temporary + ": cannot create: " + std::strerror(errno));
  const bool written = std::fwrite(text.data(), 1, text.size(), file) == text.size();
  const int write_errno = errno;
  if (std::fclose(file) != 0 || !written) {
    throw Rosbag2Error(temporary + ": cannot write: " + std::strerror(written ? errno : write_errno));
  }
  if (std::rename(temporary.c_str(), path.c_str()) != 0) {
    throw Rosbag2Error(path + ": cannot replace: " + std::strerror(errno));
  }
}

Rosbag2Writer::Statement Rosbag2Writer::prepare(const char* sql) {
  sqlite3_stmt* stmt = nullptr;
  const int rc = sqlite3_prepare_v2(db_.get(), sql, -1, &stmt, nullptr);
  Statement owned(stmt);
  if (rc != SQLITE_OK) fail(std::string("cannot prepare \"") + sql + "\"");
  return owned;
}

void Rosbag2Writer::exec(const char* sql) {
  if (sqlite3_exec(db_.get(), sql, nullptr, nullptr, nullptr) != SQLITE_OK) {
    fail(std::string("\"") + sql + "\" failed");
  }
}

std::string Rosbag2Writer::query_text(const char* sql) {
  const Statement stmt = prepare(sql);
  const int rc = sqlite3_step(stmt.get());
  if (rc == SQLITE_DONE) return {};
  if (rc != SQLITE_ROW) fail(std::string("\"") + sql + "\" failed");
  const unsigned char* text = sqlite3_column_text(stmt.get(), 0);
  return text == nullptr ? std::string() : reinterpret_cast<const char*>(text);
}

std::string Rosbag2Writer::error_text(const std::string& what) const {
  return database_path_ + ": " + what + ": " + (db_ ? sqlite3_errmsg(db_.get()) : "database closed");
}

void Rosbag2Writer::fail(const std::string& what) const { throw Rosbag2Error(error_text(what)); }

void Rosbag2Writer::require_open(const char* operation) const {
  if (!db_) throw Rosbag2Error(in_bag(directory_, std::string(operation) + " after close()"));
}

}  // namespace beaconloc::rosbag2
