#!/usr/bin/env python3
"""Writes the seed inputs of fuzz_beacon_map_msg (corpus/fuzz_beacon_map_msg/): CDR BeaconMap
samples (idl/beaconloc.idl) as a Fast DDS writer sends them: the 4-byte encapsulation header,
then plain CDR. Run: python3 tests/fuzz/make_beacon_map_seeds.py"""
import math
import os
import struct


def beacon_map(frame, beacons, big_endian=False):
    e = ">" if big_endian else "<"
    body = bytearray()
    name = frame.encode() + b"\0"
    body += struct.pack(e + "I", len(name)) + name
    body += b"\0" * (-len(body) % 4)
    body += struct.pack(e + "I", len(beacons))
    for beacon in beacons:
        beacon_id, x, y, z, group = beacon[:5]
        reach = beacon[5] if len(beacon) > 5 else (0.0, 0.0, 0.0)  # min, max, half-angle: 0 = not known
        body += b"\0" * (-len(body) % 4)
        body += struct.pack(e + "I", beacon_id)
        body += b"\0" * (-len(body) % 8)
        body += struct.pack(e + "ddd", x, y, z)
        body += struct.pack(e + "II", group, 0)  # group, frame BEACON_FRAME_MAP
        body += b"\0" * (-len(body) % 8)
        body += struct.pack(e + "ddd", *reach)
    return bytes([0, 0 if big_endian else 1, 0, 0]) + bytes(body)


def main():
    out = os.path.join(os.path.dirname(os.path.abspath(__file__)), "corpus", "fuzz_beacon_map_msg")
    os.makedirs(out, exist_ok=True)
    six = [(i, 0.5 * i, 1.2 - 0.3 * i, 2.011, 0) for i in range(1, 7)]
    seeds = {
        "default_six.bin": beacon_map("map", six),
        "big_endian.bin": beacon_map("map", six[:3], big_endian=True),
        "empty.bin": beacon_map("map", []),
        "duplicate_id.bin": beacon_map("map", [(4, 0.0, 0.0, 2.0, 0), (4, 3.0, 0.0, 2.0, 1)]),
        "non_finite.bin": beacon_map("map", [(1, math.nan, 0.0, 2.0, 0), (2, math.inf, -math.inf, 2.0, 0)]),
        "absurd.bin": beacon_map("", [(0xFFFFFFFF, 1e300, -1e300, 5e-324, 0xFFFFFFFF)]),
        "seed004_reach.bin": beacon_map("map", [(1, -0.5, 0.3, 5.4, 0, (3.5, 5.0, 0.5236)),
                                                 (2, 2.0, 0.3, 5.4, 0, (0.0, 0.0, 0.0))]),
        "bad_reach.bin": beacon_map("map", [(1, 0.0, 0.0, 5.4, 0, (5.0, 3.5, math.nan)),
                                             (2, 2.0, 0.0, 5.4, 0, (-1.0, 1e300, 7.0))]),
    }
    for name, data in seeds.items():
        with open(os.path.join(out, name), "wb") as f:
            f.write(data)


if __name__ == "__main__":
    main()
