#!/usr/bin/env python3
"""What a bridge must have published for a recording's poses, written from the ROS 2 conventions
(design/ROS2-INTEROP.md: covariances row-major 6x6 over x, y, z, roll, pitch, yaw; REP-103 yaw as a
rotation about z), not from the bridge's code: for each row of a `beaconloc record` estimate.csv
(robot_id, stamp_ns, x_m, y_m, yaw_rad, cov_00..cov_22 over x, y, yaw), the fields of its
geometry_msgs/PoseWithCovarianceStamped and of its nav_msgs/Odometry, as CSVs for
check_rosbag2.py --expect-poses / --expect-odometry. The odometry's twist and its covariance are
left unchecked here (empty cells): they are the wheels' newest report when the pose arrived
(check_rosbag2.py --twists-from-wheels checks both against the recording's wheel rows).

    ros2_expected_from_recording.py ESTIMATE_CSV POSES_OUT ODOMETRY_OUT [--map-frame map] [--base-frame base_link]
"""

import argparse
import csv
import math
import sys

PLANAR = [0, 1, 5]  # x, y, yaw among (x, y, z, roll, pitch, yaw)


def covariance36(row):
    c = [0.0] * 36
    for r in range(3):
        for k in range(3):
            c[PLANAR[r] * 6 + PLANAR[k]] = float(row["cov_%d%d" % (r, k)])
    return c


def main(argv):
    parser = argparse.ArgumentParser()
    parser.add_argument("estimate_csv")
    parser.add_argument("poses_out")
    parser.add_argument("odometry_out")
    parser.add_argument("--map-frame", default="map")
    parser.add_argument("--base-frame", default="base_link")
    args = parser.parse_args(argv)
    pose_header = ["stamp_ns", "frame_id", "x", "y", "z", "qx", "qy", "qz", "qw"] + ["cov%d" % i for i in range(36)]
    odometry_header = (["stamp_ns", "frame_id", "child_frame_id", "x", "y", "z", "qx", "qy", "qz", "qw",
                        "vx", "vy", "vz", "wx", "wy", "wz"] + ["pose_cov%d" % i for i in range(36)] +
                       ["twist_cov%d" % i for i in range(36)])
    rows = 0
    with open(args.estimate_csv, newline="") as f, open(args.poses_out, "w", newline="") as p, \
            open(args.odometry_out, "w", newline="") as o:
        poses, odometry = csv.writer(p), csv.writer(o)
        poses.writerow(pose_header)
        odometry.writerow(odometry_header)
        for row in csv.DictReader(f):
            yaw = float(row["yaw_rad"])
            pose = [float(row["x_m"]), float(row["y_m"]), 0.0, 0.0, 0.0, math.sin(yaw / 2.0), math.cos(yaw / 2.0)]
            cov = covariance36(row)
            stamp = int(row["stamp_ns"])
            poses.writerow([stamp, args.map_frame] + [repr(v) for v in pose + cov])
            odometry.writerow([stamp, args.map_frame, args.base_frame] + [repr(v) for v in pose] + [""] * 6 +
                              [repr(v) for v in cov] + [""] * 36)
            rows += 1
    if rows == 0:
        print("ros2_expected_from_recording: no pose in %s" % args.estimate_csv, file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
