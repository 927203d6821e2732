#!/usr/bin/env python3
"""Writes the seed inputs of fuzz_decoder_input (corpus/fuzz_decoder_input/): CDR RawTof
samples as a Fast DDS writer sends them, laid out for the target's FuzzedDataProvider (payload
bytes from the front, choices from the back). Run: python3 tests/fuzz/make_decoder_seeds.py"""
import os
import struct

INT64_MIN = -(1 << 63)
UNIDENTIFIED = 0xFFFFFFFF


def raw_tof(robot, beacon, receiver, fire_ns, tof_s, temp_c, seq, big_endian=False):
    """idl/beaconloc.idl RawTof in plain CDR, after the 4-byte encapsulation header."""
    e = ">" if big_endian else "<"
    body = bytearray()
    name = robot.encode() + b"\0"
    body += struct.pack(e + "I", len(name)) + name
    body += b"\0" * (-len(body) % 4)
    body += struct.pack(e + "II", beacon, receiver)
    body += b"\0" * (-len(body) % 8)
    body += struct.pack(e + "qddQ", fire_ns, tof_s, temp_c, seq)
    return bytes([0, 0 if big_endian else 1, 0, 0]) + bytes(body)


class Input:
    """Front: payloads in order. Back: one-byte choices, consumed from the end."""

    def __init__(self, ultrasonic=True):
        self.front = bytearray()
        self.back = [0 if ultrasonic else 1]  # ConsumeBool: range_scale

    def sample(self, payload):
        assert len(payload) <= 96
        self.back += [0, len(payload)]
        self.front += payload

    def duplicate(self):
        self.back.append(1)

    def shift(self, delta_ns, seq_step):
        self.back.append(2)
        raw = (delta_ns - INT64_MIN) % (1 << 64)  # ConsumeIntegral<int64_t>: min + bytes
        self.back += list(raw.to_bytes(8, "big"))
        self.back.append(seq_step)

    def beacon_map(self):
        self.back.append(3)

    def bytes(self):
        return bytes(self.front) + bytes(reversed(self.back))


def main():
    out = os.path.join(os.path.dirname(os.path.abspath(__file__)), "corpus", "fuzz_decoder_input")
    os.makedirs(out, exist_ok=True)
    seeds = {}

    s = Input()
    s.beacon_map()
    for i, beacon in enumerate((1, 2, 3)):
        s.sample(raw_tof("robot_0", beacon, i % 3, 1_000_000_000 + 200_000_000 * i, 0.0073, 22.0, i))
    s.duplicate()
    s.shift(-1_000_000_000, 1)  # a second earlier: stale
    s.shift(1_200_000_000, 1)
    seeds["map_first.bin"] = s.bytes()

    s = Input()
    for i, beacon in enumerate((2, 3, 1, 9)):
        s.sample(raw_tof("robot_1", beacon, 0, 5_000_000_000 + 200_000_000 * i, 0.006, 20.0, 10 + i))
    s.beacon_map()
    s.duplicate()
    seeds["map_later.bin"] = s.bytes()

    s = Input(ultrasonic=False)
    s.beacon_map()
    s.sample(raw_tof("r", UNIDENTIFIED, 1, 7_000_000, 0.004, 21.5, 1))
    s.sample(raw_tof("r", 1, 0, 7_200_000, -0.004, 21.5, 2))
    s.sample(raw_tof("r", 1, 0, 7_400_000, 0.004, 95.0, 3))
    s.sample(raw_tof("r", 1, 0, 7_600_000, 0.2, 20.0, 4))
    s.sample(raw_tof("robot_big_endian", 2, 2, 9_000_000_000, 0.005, 15.0, 5, big_endian=True))
    seeds["rejections.bin"] = s.bytes()

    for name, data in seeds.items():
        with open(os.path.join(out, name), "wb") as f:
            f.write(data)


if __name__ == "__main__":
    main()
