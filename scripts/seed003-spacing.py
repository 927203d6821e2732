#!/usr/bin/env python3
"""Writes examples/scenarios/seed003_scan.yaml with its beacon groups SPACING_M apart along the
path instead of 4 m (docs/accuracy-seed003.md, "Group spacing"): every group, its frame, the two
straight legs, the duration and the building move with it; nothing else changes.

    python3 scripts/seed003-spacing.py 6.5 > /tmp/seed003_6.5.yaml
    BEACONLOC_SEED003_SCENARIO=/tmp/seed003_6.5.yaml build/release/tests/beaconloc_accuracy_tests ...
"""
import math
import os
import re
import sys

SHIPPED = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "examples", "scenarios", "seed003_scan.yaml")
HALF_DIAGONAL_M = 0.35355339059  # a square of 1 m diagonal, sides along the axes
CORNER_OFFSETS = {1: (1, 1), 2: (-1, 1), 3: (-1, -1), 4: (1, -1), 5: (0, 0)}  # beacon number -> corner
SPEED_MPS, TURN_RADPS, TURN_RADIUS_M = 0.4, 0.2, 2.0


def main():
    if len(sys.argv) != 2:
        sys.exit("usage: seed003-spacing.py SPACING_M")
    s = float(sys.argv[1])
    if not 2.0 <= s <= 10.0:
        sys.exit("SPACING_M must be within [2, 10]")
    # As the shipped file: GRULPS 1 at (5.5, 2); LRULPS #1-#3 east along y = 2; #4 over the corner,
    # 0.1 m short of the spacing and 0.6 m off the first leg; #5-#7 and GRULPS 2 north of it.
    centre = {1: (5.5, 2.0)}
    for k, group in enumerate((3, 4, 5), 1):
        centre[group] = (5.5 + s * k, 2.0)
    centre[6] = (centre[5][0] + s - 0.1, 2.6)
    north_x = centre[6][0] + 0.6
    for k, group in enumerate((7, 8, 9, 2), 1):
        centre[group] = (north_x, 2.6 + s * k)
    turn_start_x = north_x - TURN_RADIUS_M
    first_leg_m = turn_start_x - 2.2  # after 1 s at 0.2 m/s from x = 2
    end_y = centre[2][1] + 3.0
    second_leg_m = end_y - 0.2 - (2.0 + TURN_RADIUS_M)
    duration_s = 1.0 + first_leg_m / SPEED_MPS + (math.pi / 2) / TURN_RADPS + second_leg_m / SPEED_MPS + 1.0

    text = open(SHIPPED).read()

    def beacon(m):
        beacon_id, group = int(m.group(1)), int(m.group(2))
        cx, cy = centre[group]
        dx, dy = CORNER_OFFSETS[beacon_id % 10]
        return "  - {id: %d, position_m: [%.11f, %.11f, 3.5], group: %d}" % (
            beacon_id, cx + dx * HALF_DIAGONAL_M, cy + dy * HALF_DIAGONAL_M, group)

    def frame(m):
        group = int(m.group(1))
        return "  - {id: %d, referenced: local, frame_pose_m: [%.3f, %.3f, %s]}" % (
            group, centre[group][0], centre[group][1], m.group(2))

    def replace(pattern, repl, count=1):
        nonlocal text
        text, n = re.subn(pattern, repl, text, flags=re.M)
        if n != count:
            sys.exit("the shipped scenario changed shape: %r matched %d times" % (pattern, n))

    replace(r"^  - \{id: (\d+), position_m: \[[^]]*\], group: (\d+)\}$", beacon, 38)
    replace(r"^  - \{id: (\d+), referenced: local, frame_pose_m: \[[^]]*, (-?[\d.]+)\]\}$", frame, 7)
    replace(r"^    - \{duration_s: [\d.]+(, linear_mps: 0.4, angular_radps: 0.0\}).*# straight.*$",
            lambda m: "    - {duration_s: %.6f%s" % (first_leg_m / SPEED_MPS, m.group(1)), 2)
    # the second straight got the first's duration above: set it
    text = text[::-1].replace(("{duration_s: %.6f" % (first_leg_m / SPEED_MPS))[::-1],
                              ("{duration_s: %.6f" % (second_leg_m / SPEED_MPS))[::-1], 1)[::-1]
    replace(r"^duration_s: [\d.]+", "duration_s: %.6f" % duration_s)
    replace(r"^  size_m: \[[^]]*\]", "  size_m: [%.1f, %.1f]" % (north_x + 2.0, end_y + 1.4))
    replace(r"\{min_m: \[0.0, 4.0\], max_m: \[[^]]*\]\}", "{min_m: [0.0, 4.0], max_m: [%.1f, %.1f]}" % (
        turn_start_x, end_y + 1.4))
    sys.stdout.write("# seed003_scan.yaml with the groups %.2f m apart (scripts/seed003-spacing.py)\n" % s + text)


if __name__ == "__main__":
    main()
