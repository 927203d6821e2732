#!/usr/bin/env python3
"""An independent reader of rosbag2 bags (sqlite3 storage, Humble's layout) written by
beaconloc's rosbag2 writer. It shares no code with the writer: the Python standard library and
yaml (python3-yaml) only, the format as rosbag2 defines it.

    check_rosbag2.py BAG_DIR [--after-kill] [--min-messages N]
                     [--expect-poses CSV] [--expect-odometry CSV] [--twists-from-wheels CSV]

Checks metadata.yaml (structure; counts and times equal the database's, or with --after-kill
never above them), the database (integrity, schema, topics, every message's topic and CDR
encapsulation header) and decodes every geometry_msgs/msg/PoseWithCovarianceStamped and
nav_msgs/msg/Odometry message in full (CDR little endian): the whole blob consumed, every float
finite, covariances symmetric. With --expect-* CSVs, every message equals its row exactly
(matched by header stamp, a stamp's messages in order; floats compared bit for bit; an empty cell
is not checked).

Message timestamps need not grow with the row id: a recorder receives topics on several threads,
and rosbag2 reads in (timestamp, id) order.

Exit status 0 when every check passes (one summary line per topic), 1 otherwise (the failures on
stderr), 2 on bad usage.
"""

import argparse
import csv
import math
import os
import sqlite3
import struct
import sys

import yaml

POSE_TYPE = "geometry_msgs/msg/PoseWithCovarianceStamped"
ODOMETRY_TYPE = "nav_msgs/msg/Odometry"
CDR_LE_HEADER = b"\x00\x01\x00\x00"
MAX_REPORTED = 12

# The tables as Humble's sqlite3 storage creates them (schema version 3):
# column -> (declared type, not null, primary key).
EXPECTED_TABLES = {
    "schema": {"schema_version": ("INTEGER", 0, 1), "ros_distro": ("TEXT", 1, 0)},
    "metadata": {"id": ("INTEGER", 0, 1), "metadata_version": ("INTEGER", 1, 0), "metadata": ("TEXT", 1, 0)},
    "topics": {
        "id": ("INTEGER", 0, 1),
        "name": ("TEXT", 1, 0),
        "type": ("TEXT", 1, 0),
        "serialization_format": ("TEXT", 1, 0),
        "offered_qos_profiles": ("TEXT", 1, 0),
    },
    "messages": {
        "id": ("INTEGER", 0, 1),
        "topic_id": ("INTEGER", 1, 0),
        "timestamp": ("INTEGER", 1, 0),
        "data": ("BLOB", 1, 0),
    },
}

QOS_KEYS = [
    "history", "depth", "reliability", "durability", "deadline", "lifespan", "liveliness",
    "liveliness_lease_duration", "avoid_ros_namespace_conventions",
]


class CheckFailed(Exception):
    pass


class Problems:
    """Collects failures; the report lists the first few of each run."""

    def __init__(self):
        self.items = []

    def add(self, text):
        self.items.append(text)

    def require(self, condition, text):
        if not condition:
            self.add(text)
        return condition


# ---------------------------------------------------------------- CDR (little endian)

class CdrReader:
    """Reads a CDR little-endian payload. Alignment is relative to the first byte after the 4-byte
    encapsulation header."""

    def __init__(self, blob):
        self.payload = blob[4:]
        self.pos = 0

    def _align(self, size):
        self.pos += (-self.pos) % size

    def _take(self, fmt, size):
        self._align(size)
        if self.pos + size > len(self.payload):
            raise CheckFailed("truncated at payload byte %d (needs %d more)" % (self.pos, size))
        (value,) = struct.unpack_from("<" + fmt, self.payload, self.pos)
        self.pos += size
        return value

    def int32(self):
        return self._take("i", 4)

    def uint32(self):
        return self._take("I", 4)

    def float64(self):
        return self._take("d", 8)

    def string(self):
        length = self.uint32()  # bytes including the terminating NUL
        if length < 1:
            raise CheckFailed("string length 0 (a CDR string holds at least its NUL)")
        if self.pos + length > len(self.payload):
            raise CheckFailed("string of %d bytes runs past the end" % length)
        raw = self.payload[self.pos:self.pos + length]
        self.pos += length
        if raw[-1] != 0 or 0 in raw[:-1]:
            raise CheckFailed("string not NUL-terminated or holding a NUL")
        try:
            return raw[:-1].decode("utf-8")
        except UnicodeDecodeError as e:
            raise CheckFailed("string not UTF-8: %s" % e)

    def finish(self):
        rest = self.payload[self.pos:]
        if len(rest) > 3 or any(rest):
            raise CheckFailed("%d bytes left after the message" % len(rest))


def read_header(r):
    sec = r.int32()
    nanosec = r.uint32()
    if nanosec >= 1_000_000_000:
        raise CheckFailed("header nanosec %d >= 1e9" % nanosec)
    return {"stamp_ns": sec * 1_000_000_000 + nanosec, "frame_id": r.string()}


def read_floats(r, names):
    return {name: r.float64() for name in names}


POSE_FIELDS = ["x", "y", "z", "qx", "qy", "qz", "qw"]
TWIST_FIELDS = ["vx", "vy", "vz", "wx", "wy", "wz"]


def read_covariance(r, prefix):
    return {"%s%d" % (prefix, i): r.float64() for i in range(36)}


def decode_pose(blob):
    r = CdrReader(blob)
    m = read_header(r)
    m.update(read_floats(r, POSE_FIELDS))
    m.update(read_covariance(r, "cov"))
    r.finish()
    return m


def decode_odometry(blob):
    r = CdrReader(blob)
    m = read_header(r)
    m["child_frame_id"] = r.string()
    m.update(read_floats(r, POSE_FIELDS))
    m.update(read_covariance(r, "pose_cov"))
    m.update(read_floats(r, TWIST_FIELDS))
    m.update(read_covariance(r, "twist_cov"))
    r.finish()
    return m


DECODERS = {POSE_TYPE: decode_pose, ODOMETRY_TYPE: decode_odometry}
COVARIANCE_PREFIXES = {POSE_TYPE: ["cov"], ODOMETRY_TYPE: ["pose_cov", "twist_cov"]}


def check_values(message, type_name):
    for key, value in message.items():
        if isinstance(value, float) and not math.isfinite(value):
            raise CheckFailed("%s is not finite (%r)" % (key, value))
    for prefix in COVARIANCE_PREFIXES[type_name]:
        for row in range(6):
            for col in range(row + 1, 6):
                a = message["%s%d" % (prefix, row * 6 + col)]
                b = message["%s%d" % (prefix, col * 6 + row)]
                if a != b:
                    raise CheckFailed("%s not symmetric at (%d,%d): %r != %r" % (prefix, row, col, a, b))


# ---------------------------------------------------------------- metadata.yaml

def load_metadata(bag_dir, problems):
    path = os.path.join(bag_dir, "metadata.yaml")
    if not os.path.isfile(path):
        raise CheckFailed("%s: missing" % path)
    with open(path, "r", encoding="utf-8") as f:
        try:
            document = yaml.safe_load(f)
        except yaml.YAMLError as e:
            raise CheckFailed("%s: not valid YAML: %s" % (path, e))
    if not isinstance(document, dict) or not isinstance(document.get("rosbag2_bagfile_information"), dict):
        raise CheckFailed("%s: no rosbag2_bagfile_information mapping" % path)
    info = document["rosbag2_bagfile_information"]
    check_metadata_structure(info, problems, path)
    return info


def is_int(value):
    return isinstance(value, int) and not isinstance(value, bool)


def nanoseconds(node, key):
    if not isinstance(node, dict) or not is_int(node.get(key)) or node[key] < 0:
        raise CheckFailed("expected {%s: non-negative integer}, got %r" % (key, node))
    return node[key]


def check_qos_profiles(text, where, problems):
    if not isinstance(text, str):
        problems.add("%s: offered_qos_profiles is not a string" % where)
        return
    try:
        profiles = yaml.safe_load(text)
    except yaml.YAMLError as e:
        problems.add("%s: offered_qos_profiles is not YAML: %s" % (where, e))
        return
    if not isinstance(profiles, list) or len(profiles) != 1 or not isinstance(profiles[0], dict):
        problems.add("%s: offered_qos_profiles is not a sequence of one profile" % where)
        return
    p = profiles[0]
    if not problems.require(sorted(p) == sorted(QOS_KEYS), "%s: QoS keys %s" % (where, sorted(p))):
        return
    problems.require(p["history"] == 1, "%s: history %r, not 1 (keep last)" % (where, p["history"]))
    problems.require(is_int(p["depth"]) and p["depth"] >= 0, "%s: depth %r" % (where, p["depth"]))
    problems.require(p["reliability"] in (1, 2), "%s: reliability %r" % (where, p["reliability"]))
    problems.require(p["durability"] in (1, 2), "%s: durability %r" % (where, p["durability"]))
    problems.require(p["liveliness"] == 1, "%s: liveliness %r" % (where, p["liveliness"]))
    for key in ("deadline", "lifespan", "liveliness_lease_duration"):
        d = p[key]
        problems.require(isinstance(d, dict) and sorted(d) == ["nsec", "sec"] and is_int(d["sec"]) and
                         is_int(d["nsec"]), "%s: %s is %r" % (where, key, d))
    problems.require(p["avoid_ros_namespace_conventions"] is False,
                     "%s: avoid_ros_namespace_conventions %r" % (where, p["avoid_ros_namespace_conventions"]))


def check_metadata_structure(info, problems, path):
    problems.require(info.get("version") == 5, "%s: version %r, not 5" % (path, info.get("version")))
    problems.require(info.get("storage_identifier") == "sqlite3",
                     "%s: storage_identifier %r" % (path, info.get("storage_identifier")))
    for key in ("compression_format", "compression_mode"):
        problems.require(info.get(key) == "", "%s: %s %r, not \"\"" % (path, key, info.get(key)))
    paths = info.get("relative_file_paths")
    if not isinstance(paths, list) or len(paths) != 1 or not isinstance(paths[0], str):
        raise CheckFailed("%s: relative_file_paths %r is not a list of one file" % (path, paths))
    nanoseconds(info.get("duration"), "nanoseconds")
    nanoseconds(info.get("starting_time"), "nanoseconds_since_epoch")
    if not is_int(info.get("message_count")):
        raise CheckFailed("%s: message_count %r" % (path, info.get("message_count")))
    topics = info.get("topics_with_message_count")
    if not isinstance(topics, list):
        raise CheckFailed("%s: topics_with_message_count is not a list" % path)
    total = 0
    for entry in topics:
        meta = entry.get("topic_metadata") if isinstance(entry, dict) else None
        if not isinstance(meta, dict) or not is_int(entry.get("message_count")):
            raise CheckFailed("%s: topics_with_message_count entry %r" % (path, entry))
        for key in ("name", "type"):
            problems.require(isinstance(meta.get(key), str) and meta[key], "%s: topic %s %r" % (path, key, meta))
        problems.require(meta.get("serialization_format") == "cdr", "%s: topic %r not cdr" % (path, meta.get("name")))
        check_qos_profiles(meta.get("offered_qos_profiles"), "%s topic %r" % (path, meta.get("name")), problems)
        total += entry["message_count"]
    problems.require(total == info["message_count"],
                     "%s: message_count %d != sum over topics %d" % (path, info["message_count"], total))
    files = info.get("files")
    if not isinstance(files, list) or len(files) != 1 or not isinstance(files[0], dict):
        raise CheckFailed("%s: files %r is not a list of one file" % (path, files))
    f = files[0]
    problems.require(f.get("path") == paths[0], "%s: files[0].path %r != %r" % (path, f.get("path"), paths[0]))
    problems.require(nanoseconds(f.get("starting_time"), "nanoseconds_since_epoch") ==
                     info["starting_time"]["nanoseconds_since_epoch"], "%s: files[0].starting_time" % path)
    problems.require(nanoseconds(f.get("duration"), "nanoseconds") == info["duration"]["nanoseconds"],
                     "%s: files[0].duration" % path)
    problems.require(f.get("message_count") == info["message_count"], "%s: files[0].message_count" % path)


# ---------------------------------------------------------------- the database

def open_read_only(db_path):
    if not os.path.isfile(db_path):
        raise CheckFailed("%s: missing" % db_path)
    return sqlite3.connect("file:%s?mode=ro" % db_path, uri=True)


def check_tables(db, db_path, problems):
    for table, columns in EXPECTED_TABLES.items():
        rows = db.execute("PRAGMA table_info(%s)" % table).fetchall()
        found = {name: (decl.upper(), notnull, 1 if pk else 0) for _, name, decl, notnull, _, pk in rows}
        problems.require(found == columns,
                         "%s: table %s has columns %r, expected %r" % (db_path, table, found, columns))
    index = db.execute("SELECT tbl_name FROM sqlite_master WHERE type='index' AND name='timestamp_idx'").fetchall()
    problems.require(index == [("messages",)], "%s: no index timestamp_idx on messages" % db_path)
    if index:
        columns = [row[2] for row in db.execute("PRAGMA index_info(timestamp_idx)")]
        problems.require(columns == ["timestamp"], "%s: timestamp_idx covers %r" % (db_path, columns))


def read_database(db_path, problems):
    """Returns (topics by id, messages in id order, metadata rows)."""
    db = open_read_only(db_path)
    try:
        integrity = db.execute("PRAGMA integrity_check").fetchall()
        if integrity != [("ok",)]:
            raise CheckFailed("%s: integrity_check: %r" % (db_path, integrity[:5]))
        check_tables(db, db_path, problems)
        schema = db.execute("SELECT schema_version, ros_distro FROM schema").fetchall()
        if len(schema) != 1 or schema[0][0] != 3 or not isinstance(schema[0][1], str) or not schema[0][1]:
            problems.add("%s: schema rows %r, expected one (3, <ros_distro>)" % (db_path, schema))
        topics = {}
        for topic_id, name, type_name, fmt, qos in db.execute(
                "SELECT id, name, type, serialization_format, offered_qos_profiles FROM topics ORDER BY id"):
            problems.require(fmt == "cdr", "%s: topic %r serialization_format %r" % (db_path, name, fmt))
            problems.require(isinstance(name, str) and name.startswith("/"), "%s: topic name %r" % (db_path, name))
            problems.require(all(t["name"] != name for t in topics.values()), "%s: topic %r twice" % (db_path, name))
            check_qos_profiles(qos, "%s topic %r" % (db_path, name), problems)
            topics[topic_id] = {"name": name, "type": type_name, "qos": qos}
        messages = db.execute("SELECT id, topic_id, timestamp, data FROM messages ORDER BY id").fetchall()
        metadata_rows = db.execute("SELECT metadata_version, metadata FROM metadata ORDER BY id").fetchall()
    finally:
        db.close()
    return topics, messages, metadata_rows


def check_messages(topics, messages, db_path, problems):
    """Decodes every message; returns {topic id: [(bag timestamp, decoded or None)]}."""
    by_topic = {topic_id: [] for topic_id in topics}
    for row_id, topic_id, timestamp, data in messages:
        where = "%s: message id %d" % (db_path, row_id)
        if topic_id not in topics:
            problems.add("%s: topic_id %r not in topics" % (where, topic_id))
            continue
        if not is_int(timestamp) or timestamp < 0:
            problems.add("%s: timestamp %r" % (where, timestamp))
            continue
        # Counted whatever its content (the counts are the database's), compared only when decoded.
        decoded = None
        type_name = topics[topic_id]["type"]
        if not isinstance(data, bytes) or data[:4] != CDR_LE_HEADER:
            problems.add("%s: no CDR little-endian encapsulation header (%r)" % (where, bytes(data[:4])))
        elif type_name in DECODERS:
            try:
                decoded = DECODERS[type_name](data)
                check_values(decoded, type_name)
            except CheckFailed as e:
                problems.add("%s (%s): %s" % (where, type_name, e))
                decoded = None
        by_topic[topic_id].append((timestamp, decoded))
    return by_topic


def check_counts(info, topics, by_topic, after_kill, problems):
    db_counts = {t["name"]: len(by_topic[i]) for i, t in topics.items()}
    db_total = sum(db_counts.values())
    stamps = [s for rows in by_topic.values() for s, _ in rows]
    meta_start = info["starting_time"]["nanoseconds_since_epoch"]
    meta_end = meta_start + info["duration"]["nanoseconds"]
    for entry in info["topics_with_message_count"]:
        meta = entry["topic_metadata"]
        name, count = meta["name"], entry["message_count"]
        db_topic = next((t for t in topics.values() if t["name"] == name), None)
        if not problems.require(db_topic is not None, "metadata.yaml topic %r is not in the database" % name):
            continue
        problems.require(meta["type"] == db_topic["type"], "topic %r: type %r in metadata.yaml, %r in the database"
                         % (name, meta["type"], db_topic["type"]))
        problems.require(meta["offered_qos_profiles"] == db_topic["qos"],
                         "topic %r: offered_qos_profiles differ between metadata.yaml and the database" % name)
        if after_kill:
            problems.require(count <= db_counts[name], "topic %r: metadata.yaml counts %d, the database holds %d"
                             % (name, count, db_counts[name]))
        else:
            problems.require(count == db_counts[name], "topic %r: metadata.yaml counts %d, the database holds %d"
                             % (name, count, db_counts[name]))
    if after_kill:
        problems.require(info["message_count"] <= db_total, "metadata.yaml counts %d messages, the database holds %d"
                         % (info["message_count"], db_total))
        if info["message_count"] > 0:
            # Written from a prefix of the messages: its span lies within the database's.
            problems.require(min(stamps) <= meta_start and meta_end <= max(stamps),
                             "metadata.yaml time span [%d, %d] outside the database's [%d, %d]"
                             % (meta_start, meta_end, min(stamps), max(stamps)))
    else:
        names = sorted(e["topic_metadata"]["name"] for e in info["topics_with_message_count"])
        problems.require(names == sorted(db_counts), "metadata.yaml topics %r, database topics %r"
                         % (names, sorted(db_counts)))
        problems.require(info["message_count"] == db_total, "metadata.yaml counts %d messages, the database holds %d"
                         % (info["message_count"], db_total))
        start, end = (min(stamps), max(stamps)) if stamps else (0, 0)
        problems.require((meta_start, meta_end) == (start, end), "metadata.yaml time span [%d, %d], the database's"
                         " [%d, %d]" % (meta_start, meta_end, start, end))


def check_metadata_rows(metadata_rows, info, after_kill, problems):
    if after_kill and not metadata_rows:
        return  # written at close only
    if not problems.require(len(metadata_rows) == 1, "metadata table holds %d rows, expected 1"
                            % len(metadata_rows)):
        return
    version, text = metadata_rows[0]
    problems.require(version == 5, "metadata table: metadata_version %r" % version)
    try:
        row = yaml.safe_load(text)
    except yaml.YAMLError as e:
        problems.add("metadata table: not YAML: %s" % e)
        return
    # The BagMetadata mapping itself (Iron and Jazzy decode it without a root key).
    problems.require(row == info, "metadata table: differs from metadata.yaml's rosbag2_bagfile_information")


# ---------------------------------------------------------------- expectations

def float_bits(value):
    return struct.pack("<d", value)


def load_expected(path, string_fields, float_fields):
    """Rows by header stamp, in file order: a stamp may come twice (a pose corrected at its stamp
    is published again). An empty float cell is not checked."""
    rows = {}
    with open(path, newline="", encoding="utf-8") as f:
        reader = csv.DictReader(f)
        missing = [c for c in ["stamp_ns"] + string_fields + float_fields if c not in (reader.fieldnames or [])]
        if missing:
            raise CheckFailed("%s: missing columns %s" % (path, missing))
        for line in reader:
            stamp = int(line["stamp_ns"])
            row = {"stamp_ns": stamp}
            row.update({k: line[k] for k in string_fields})
            row.update({k: (float(line[k]) if line[k] != "" else None) for k in float_fields})
            rows.setdefault(stamp, []).append(row)
    return rows


def compare_expected(path, expected, decoded, type_name, string_fields, float_fields, problems):
    """Each stamp's messages, in the bag's order, against that stamp's rows, in the file's order."""
    mismatches = []
    by_stamp = {}
    for m in decoded:
        by_stamp.setdefault(m["stamp_ns"], []).append(m)
    for stamp in sorted(set(expected) - set(by_stamp)):
        mismatches.append("stamp %d expected, not in the bag" % stamp)
    for stamp in sorted(set(by_stamp) - set(expected)):
        mismatches.append("stamp %d in the bag, not expected" % stamp)
    for stamp in sorted(set(expected) & set(by_stamp)):
        wants, gots = expected[stamp], by_stamp[stamp]
        if len(wants) != len(gots):
            mismatches.append("stamp %d: %d %s messages, %d expected" % (stamp, len(gots), type_name, len(wants)))
            continue
        for want, got in zip(wants, gots):
            for k in string_fields:
                if want[k] != got[k]:
                    mismatches.append("stamp %d: %s expected %r, got %r" % (stamp, k, want[k], got[k]))
            for k in float_fields:
                if want[k] is not None and float_bits(want[k]) != float_bits(got[k]):
                    mismatches.append("stamp %d: %s expected %r, got %r" % (stamp, k, want[k], got[k]))
    for text in mismatches[:MAX_REPORTED]:
        problems.add("%s: %s" % (path, text))
    if len(mismatches) > MAX_REPORTED:
        problems.add("%s: ... %d more mismatches" % (path, len(mismatches) - MAX_REPORTED))


def decoded_of_type(topics, by_topic, type_name):
    """The messages of that type that decoded (the others are failures already)."""
    return [m for i, t in topics.items() if t["type"] == type_name for _, m in by_topic[i] if m is not None]


# ---------------------------------------------------------------- main

def check(args):
    problems = Problems()
    info = load_metadata(args.bag_dir, problems)
    db_path = os.path.join(args.bag_dir, info["relative_file_paths"][0])
    topics, messages, metadata_rows = read_database(db_path, problems)
    by_topic = check_messages(topics, messages, db_path, problems)
    check_counts(info, topics, by_topic, args.after_kill, problems)
    check_metadata_rows(metadata_rows, info, args.after_kill, problems)
    if args.min_messages is not None:
        problems.require(len(messages) >= args.min_messages, "%d messages, fewer than --min-messages %d"
                         % (len(messages), args.min_messages))
    pose_floats = POSE_FIELDS + ["cov%d" % i for i in range(36)]
    if args.expect_poses:
        compare_expected(args.expect_poses, load_expected(args.expect_poses, ["frame_id"], pose_floats),
                         decoded_of_type(topics, by_topic, POSE_TYPE), POSE_TYPE, ["frame_id"], pose_floats,
                         problems)
    odometry_floats = (POSE_FIELDS + TWIST_FIELDS + ["pose_cov%d" % i for i in range(36)] +
                       ["twist_cov%d" % i for i in range(36)])
    if args.expect_odometry:
        strings = ["frame_id", "child_frame_id"]
        compare_expected(args.expect_odometry, load_expected(args.expect_odometry, strings, odometry_floats),
                         decoded_of_type(topics, by_topic, ODOMETRY_TYPE), ODOMETRY_TYPE, strings,
                         odometry_floats, problems)
    if args.twists_from_wheels:
        check_twists(args.twists_from_wheels, decoded_of_type(topics, by_topic, ODOMETRY_TYPE), problems)
    return problems, topics, by_topic


# A twist the bridge has not heard yet (no wheel odometry before the pose): (0, 0), a variance
# this large on the diagonal (bridge/odom_frame.hpp kUnknownTwistVariance), never a certain one.
UNKNOWN_TWIST_VARIANCE = 1e6
TWIST_VX, TWIST_WZ = 0, 5  # rows of the twist covariance: vx, vy, vz, wx, wy, wz


def twist_covariance(right_var, cross, left_var, base):
    """Cov(v, omega) of wheel speeds with covariance [[right_var, cross], [cross, left_var]], through
    v = (right + left) / 2, omega = (right - left) / base, as (var_v, cov_v_omega, var_omega): J C J^T
    with J = [[1/2, 1/2], [1/base, -1/base]], multiplied out by hand."""
    return ((right_var + 2.0 * cross + left_var) / 4.0, (right_var - left_var) / (2.0 * base),
            (right_var - 2.0 * cross + left_var) / (base * base))


def check_twists(path, decoded, problems):
    """Each Odometry message's twist is one the robot's wheels reported: (v, omega) =
    ((right + left) / 2, (right - left) / wheel_base) of a row of a recording's odometry.csv, the
    other components 0 (a planar robot), and its covariance that row's wheel covariance carried to
    (v, omega) at (vx, wz), 0 elsewhere; or, before any wheel row reached the bridge, (0, 0) with
    the unknown variance. Which row depends on when the pose met the odometry."""
    reported = {}
    with open(path, newline="", encoding="utf-8") as f:
        for line in csv.DictReader(f):
            right, left = float(line["wheel_velocity_right_mps"]), float(line["wheel_velocity_left_mps"])
            base = float(line["wheel_base_m"])
            key = (float_bits((right + left) / 2.0), float_bits((right - left) / base))
            reported.setdefault(key, []).append(twist_covariance(
                float(line["var_right"]), float(line["cov_right_left"]), float(line["var_left"]), base))

    def block(m):
        return (m["twist_cov%d" % (TWIST_VX * 6 + TWIST_VX)], m["twist_cov%d" % (TWIST_VX * 6 + TWIST_WZ)],
                m["twist_cov%d" % (TWIST_WZ * 6 + TWIST_WZ)])

    def fits(m):
        if any(m[k] != 0.0 for k in ("vy", "vz", "wx", "wy")):
            return False
        if m["twist_cov%d" % (TWIST_VX * 6 + TWIST_WZ)] != m["twist_cov%d" % (TWIST_WZ * 6 + TWIST_VX)]:
            return False
        inside = {TWIST_VX * 6 + TWIST_VX, TWIST_VX * 6 + TWIST_WZ, TWIST_WZ * 6 + TWIST_VX, TWIST_WZ * 6 + TWIST_WZ}
        if any(m["twist_cov%d" % i] != 0.0 for i in range(36) if i not in inside):
            return False
        if (m["vx"], m["wz"]) == (0.0, 0.0) and block(m) == (UNKNOWN_TWIST_VARIANCE, 0.0, UNKNOWN_TWIST_VARIANCE):
            return True
        candidates = reported.get((float_bits(m["vx"]), float_bits(m["wz"])), [])
        # Bit for bit: the bridge computes the same expressions in the same order (odom_frame.cpp).
        return any(tuple(float_bits(v) for v in block(m)) == tuple(float_bits(v) for v in c) for c in candidates)

    bad = [m for m in decoded if not fits(m)]
    for m in bad[:MAX_REPORTED]:
        problems.add("%s: odometry at stamp %d has twist (%r, %r, %r; %r, %r, %r) with covariance (%r, %r, %r) at"
                     " (vx, wz), no wheel row reported it"
                     % ((path, m["stamp_ns"], m["vx"], m["vy"], m["vz"], m["wx"], m["wy"], m["wz"]) + block(m)))


def main(argv):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("bag_dir")
    parser.add_argument("--after-kill", action="store_true",
                        help="the writer was killed: metadata.yaml may count fewer messages than the database")
    parser.add_argument("--min-messages", type=int)
    parser.add_argument("--expect-poses", help="CSV: stamp_ns,frame_id,x,y,z,qx,qy,qz,qw,cov0..cov35")
    parser.add_argument("--expect-odometry", help="CSV: stamp_ns,frame_id,child_frame_id,x..qw,vx..wz,"
                        "pose_cov0..35,twist_cov0..35")
    parser.add_argument("--twists-from-wheels", help="a recording's odometry.csv: every Odometry twist is one of its"
                        " rows' (v, omega)")
    args = parser.parse_args(argv)
    try:
        problems, topics, by_topic = check(args)
    except CheckFailed as e:
        print("check_rosbag2: FAILED: %s" % e, file=sys.stderr)
        return 1
    except (sqlite3.Error, OSError, ValueError) as e:
        print("check_rosbag2: FAILED: %s: %s" % (type(e).__name__, e), file=sys.stderr)
        return 1
    if problems.items:
        for text in problems.items[:MAX_REPORTED]:
            print("check_rosbag2: FAILED: %s" % text, file=sys.stderr)
        if len(problems.items) > MAX_REPORTED:
            print("check_rosbag2: ... %d more failures" % (len(problems.items) - MAX_REPORTED), file=sys.stderr)
        return 1
    for topic_id, t in topics.items():
        stamps = sorted(s for s, _ in by_topic[topic_id])
        span = "first %d, last %d" % (stamps[0], stamps[-1]) if stamps else "no stamps"
        print("%s (%s): %d messages, %s" % (t["name"], t["type"], len(stamps), span))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
