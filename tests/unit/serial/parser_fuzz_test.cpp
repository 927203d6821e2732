// FrameParser against a fixed-seed stream of 200k bytes: good frames interleaved with random
// garbage (rich in sync bytes), frames damaged in one byte, frames cut short, frames refused
// after their checksum and packets we do not use, read in random slices. It never crashes, never
// yields a frame that was not sent, yields every good frame in order, counts what it refused, and
// never holds more than one maximum-size frame.
#include <gtest/gtest.h>

#include <random>
#include <vector>

#include "frame_encoder.hpp"
#include "frame_parser.hpp"

namespace beaconloc::serial {
namespace {

using Bytes = std::vector<std::uint8_t>;

struct Stream {
  Bytes bytes;
  std::vector<Frame> sent;          // the good frames, in order (arrival not set)
  std::uint64_t damaged = 0;        // frames damaged or cut: never yielded
  std::uint64_t refused_whole = 0;  // checksum good, refused (reserved bits)
  std::uint64_t unused = 0;
  std::uint64_t framed_bytes = 0;  // bytes of frames whose checksum holds
};

class Generator {
 public:
  Generator(Protocol protocol, std::uint64_t seed) : protocol_(protocol), random_(seed) {}

  Stream generate(std::size_t size) {
    Stream s;
    while (s.bytes.size() < size) {
      const int pick = uniform(0, 99);
      if (pick < 30) {
        garbage(s.bytes);
      } else if (pick < 80) {
        Frame frame;
        const Bytes bytes = good_frame(frame);
        append(s.bytes, bytes);
        s.sent.push_back(frame);
        s.framed_bytes += bytes.size();
      } else if (pick < 88) {
        Frame unused;
        Bytes bytes = good_frame(unused);
        bytes[static_cast<std::size_t>(uniform(0, static_cast<int>(bytes.size()) - 1))] ^=
            static_cast<std::uint8_t>(1 << uniform(0, 7));
        append(s.bytes, bytes);
        ++s.damaged;
      } else if (pick < 94) {
        Frame unused;
        const Bytes bytes = good_frame(unused);
        append(s.bytes, Bytes(bytes.begin(), bytes.begin() + uniform(1, static_cast<int>(bytes.size()) - 1)));
        ++s.damaged;
      } else {
        const Bytes bytes = valid_but_not_taken();
        append(s.bytes, bytes);
        s.framed_bytes += bytes.size();
        if (protocol_ == Protocol::kBeaconloc) {
          ++s.refused_whole;
        } else {
          ++s.unused;
        }
      }
    }
    return s;
  }

  int uniform(int lo, int hi) { return std::uniform_int_distribution<int>(lo, hi)(random_); }

 private:
  static void append(Bytes& to, const Bytes& bytes) { to.insert(to.end(), bytes.begin(), bytes.end()); }
  std::uint32_t u32() { return static_cast<std::uint32_t>(random_()); }
  std::uint8_t byte() { return static_cast<std::uint8_t>(uniform(0, 255)); }

  // One in four bytes a sync byte of either protocol: false starts galore.
  void garbage(Bytes& to) {
    static const std::uint8_t kSyncs[] = {0xB7, 0x4C, 0xFF, 0x47, 0x4A, 0x01, 0x04, 0x00};
    const int n = uniform(1, 64);
    for (int i = 0; i < n; ++i) to.push_back(uniform(0, 3) == 0 ? kSyncs[uniform(0, 7)] : byte());
  }

  Bytes good_frame(Frame& frame) {
    if (protocol_ == Protocol::kMarvelmind) {
      DistancesFrame d;
      d.stamp_ms = u32();
      d.hedge_address = byte();
      const int slots = uniform(0, 4);
      for (int i = 0; i < slots; ++i) d.slots.push_back({static_cast<std::uint8_t>(uniform(1, 255)), u32()});
      frame.body = d;
      return encode_marvelmind_distances(d);
    }
    const std::uint8_t sequence = sequence_++;
    frame.sequence = sequence;
    switch (uniform(0, 2)) {
      case 0: {
        const bool has_temperature = uniform(0, 1) == 1;
        TofFrame t{u32(),  u32(),           static_cast<std::uint16_t>(uniform(0, 65535)),
                   byte(), has_temperature, has_temperature ? uniform(-32768, 32767) / 100.0 : 0.0};
        frame.body = t;
        return encode(t, sequence);
      }
      case 1: {
        OdometryFrame o{u32(), static_cast<std::int32_t>(u32()) / 1e6, static_cast<std::int32_t>(u32()) / 1e6,
                        u32() / 1e6};
        frame.body = o;
        return encode(o, sequence);
      }
      default: {
        HeartbeatFrame h{u32()};
        frame.body = h;
        return encode(h, sequence);
      }
    }
  }

  Bytes valid_but_not_taken() {
    if (protocol_ == Protocol::kMarvelmind) {
      static const std::uint16_t kCodes[] = {0x0001, 0x0011, 0x0002, 0x0003, 0x0005, 0x0007, 0x0084};
      Bytes payload(static_cast<std::size_t>(uniform(0, 80)));
      for (auto& b : payload) b = byte();
      return encode_marvelmind_raw(0x47, kCodes[uniform(0, 6)], payload);
    }
    Bytes payload(16);
    for (auto& b : payload) b = byte();
    payload[11] = static_cast<std::uint8_t>(payload[11] | 0x02);  // a reserved flag bit
    return encode_beaconloc_raw(1, 0x01, sequence_++, payload);
  }

  Protocol protocol_;
  std::mt19937_64 random_;
  std::uint8_t sequence_ = 0;
};

void fuzz(Protocol protocol, std::uint64_t seed) {
  Generator generator(protocol, seed);
  const Stream s = generator.generate(200'000);
  FrameParser parser(protocol);
  std::vector<Frame> out;
  std::size_t at = 0;
  StampNs read = 0;
  while (at < s.bytes.size()) {
    const std::size_t n = std::min(s.bytes.size() - at, static_cast<std::size_t>(generator.uniform(1, 300)));
    parser.push(s.bytes.data() + at, n, ++read, out);
    at += n;
    ASSERT_LE(parser.pending_bytes(), FrameParser::max_frame_bytes(protocol));
  }
  // Every good frame, in order, and nothing else.
  ASSERT_EQ(out.size(), s.sent.size());
  for (std::size_t i = 0; i < out.size(); ++i) {
    ASSERT_TRUE(out[i].body == s.sent[i].body) << "frame " << i;
    ASSERT_EQ(out[i].sequence, s.sent[i].sequence) << "frame " << i;
  }
  const auto& c = parser.counts();
  EXPECT_EQ(c.frames, s.sent.size());
  EXPECT_EQ(c.unused_frames, s.unused);
  EXPECT_EQ(c.rejections(FrameRejection::kReservedBitsSet), s.refused_whole);
  EXPECT_GT(c.rejections(FrameRejection::kBadChecksum), 0u);
  EXPECT_GT(c.rejections(FrameRejection::kGarbage), 0u);
  EXPECT_EQ(c.bytes, s.bytes.size());
  EXPECT_EQ(c.bytes, s.framed_bytes + c.garbage_bytes + parser.pending_bytes());
  // Each damaged or cut frame took a sequence number that never arrived.
  if (protocol == Protocol::kBeaconloc) {
    EXPECT_EQ(c.frames_lost, s.damaged);
  }
}

TEST(SerialFrameParserFuzz, BeaconlocStreamOfGarbageAndFramesYieldsExactlyTheGoodFrames) {
  fuzz(Protocol::kBeaconloc, 20261205);
}

TEST(SerialFrameParserFuzz, MarvelmindStreamOfGarbageAndPacketsYieldsExactlyTheGoodPackets) {
  fuzz(Protocol::kMarvelmind, 20261205);
}

}  // namespace
}  // namespace beaconloc::serial
