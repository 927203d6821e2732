// FrameParser's resynchronization rules (docs/serial-protocol.md, "Finding frames"), for both
// protocols: garbage before a sync, a frame found inside a refused one, any split of the bytes
// into reads giving the same frames and counts, and every byte accounted for.
#include <gtest/gtest.h>

#include <vector>

#include "frame_encoder.hpp"
#include "frame_parser.hpp"

namespace beaconloc::serial {
namespace {

using Bytes = std::vector<std::uint8_t>;

void append(Bytes& to, const Bytes& bytes) { to.insert(to.end(), bytes.begin(), bytes.end()); }

std::uint64_t rejected(const FrameParser& parser, FrameRejection reason) {
  return parser.counts().rejections(reason);
}

// What a parse gives that does not depend on the reads: frames without arrival, and the counts.
struct Outcome {
  std::vector<Frame> frames;
  FrameParser::Counts counts;
  std::size_t pending = 0;
};

bool same(const Outcome& a, const Outcome& b) {
  if (a.frames.size() != b.frames.size() || a.pending != b.pending) return false;
  for (std::size_t i = 0; i < a.frames.size(); ++i) {
    if (!(a.frames[i].body == b.frames[i].body) || a.frames[i].sequence != b.frames[i].sequence) return false;
  }
  return a.counts.bytes == b.counts.bytes && a.counts.frames == b.counts.frames &&
         a.counts.unused_frames == b.counts.unused_frames &&
         a.counts.garbage_bytes == b.counts.garbage_bytes && a.counts.frames_lost == b.counts.frames_lost &&
         a.counts.rejected == b.counts.rejected;
}

// The bytes pushed in reads that end at each of `cuts` (ascending), then the rest.
Outcome parse_cut(Protocol protocol, const Bytes& bytes, const std::vector<std::size_t>& cuts) {
  FrameParser parser(protocol);
  Outcome outcome;
  std::size_t begin = 0;
  StampNs read = 0;
  for (std::size_t cut : cuts) {
    parser.push(bytes.data() + begin, cut - begin, ++read, outcome.frames);
    begin = cut;
  }
  parser.push(bytes.data() + begin, bytes.size() - begin, ++read, outcome.frames);
  outcome.counts = parser.counts();
  outcome.pending = parser.pending_bytes();
  return outcome;
}

Bytes corrupted(Bytes frame, std::size_t at) {
  frame[at] ^= 0x10;
  return frame;
}

// Every fault of the beaconloc protocol, and good frames, in one line.
Bytes beaconloc_line() {
  Bytes line = {0x00, 0xB7, 0xB7, 0x13, 0x4C, 0xFF};  // garbage, with a lone first sync byte
  append(line, encode(HeartbeatFrame{100}, 0));
  append(line, corrupted(encode(TofFrame{1, 2, 3, 4, true, 20.0}, 1), 12));  // bad checksum
  append(line, encode(TofFrame{5, 6, 7, 8, false, 0.0}, 2));
  append(line, {0xB7, 0x4C, 0x01, 0x01, 0x03, 0xFF});  // bad length, refused on its header
  append(line, encode(OdometryFrame{9, 0.5, -0.5, 0.3}, 3));
  append(line, {0xB7, 0x4C, 0x07});  // unknown version
  const Bytes cut = encode(TofFrame{10, 11, 12, 13, false, 0.0}, 4);
  append(line, Bytes(cut.begin(), cut.begin() + 11));  // cut off: the next frame starts inside it
  append(line, encode(HeartbeatFrame{200}, 5));
  append(line, encode(HeartbeatFrame{300}, 9));  // 3 frames lost
  append(line, {0x01, 0x02});
  append(line, encode(HeartbeatFrame{400}, 10));
  append(line, {0xB7, 0x4C, 0x01});  // pending at the end
  return line;
}

Bytes marvelmind_line() {
  DistancesFrame distances;
  distances.stamp_ms = 777;
  distances.hedge_address = 9;
  distances.slots = {{1, 1000}, {2, 2000}};
  Bytes line = {0x47, 0xFF, 0xFF, 0x12, 0x00};  // garbage, with lone address bytes
  append(line, encode_marvelmind_distances(distances));
  append(line, corrupted(encode_marvelmind_distances(distances), 20));
  append(line, encode_marvelmind_raw(0x47, 0x0011, Bytes(22, 0x33)));  // a position: unused
  append(line, {0xFF, 0x47, 0x04, 0x00, 0xFF});                        // distances of 255 bytes
  const Bytes cut = encode_marvelmind_distances(distances);
  append(line, Bytes(cut.begin(), cut.begin() + 17));
  append(line, encode_marvelmind_distances(distances));
  append(line, {0xFF, 0x47, 0x01});
  return line;
}

TEST(SerialFrameResync, BytesBeforeASyncAreGarbageCountedAsOneRunAndByTheByte) {
  for (Protocol protocol : {Protocol::kBeaconloc, Protocol::kMarvelmind}) {
    FrameParser parser(protocol);
    Bytes line = protocol == Protocol::kBeaconloc ? Bytes{0x00, 0xB7, 0x11, 0xB7, 0xB7, 0x4D, 0x4C}
                                                  : Bytes{0x00, 0xFF, 0x11, 0xFF, 0xFF, 0x48, 0x47};
    const Bytes frame = protocol == Protocol::kBeaconloc ? encode(HeartbeatFrame{1}, 0)
                                                         : encode_marvelmind_distances(DistancesFrame{});
    append(line, frame);
    std::vector<Frame> out;
    parser.push(line.data(), line.size(), 0, out);
    EXPECT_EQ(out.size(), 1u);
    EXPECT_EQ(rejected(parser, FrameRejection::kGarbage), 1u);
    EXPECT_EQ(parser.counts().garbage_bytes, 7u);
    // After a frame, another run is another count.
    const Bytes more = {0x01, 0x02, 0x03};
    parser.push(more.data(), more.size(), 0, out);
    parser.push(more.data(), more.size(), 0, out);  // the same run, over two reads
    EXPECT_EQ(rejected(parser, FrameRejection::kGarbage), 2u);
    EXPECT_EQ(parser.counts().garbage_bytes, 13u);
  }
}

// A frame cut short (a receiver reset mid-frame) swallows the start of the next as its own
// payload; its checksum fails and the search restarts at its second byte, finding the frame that
// began inside it. Its tail is that refusal's: no garbage run counted for it.
TEST(SerialFrameResync, AGoodFrameBeginningInsideACorruptedFrameIsFound) {
  const Bytes cut = encode(TofFrame{1, 2, 3, 4, false, 0.0}, 0);
  Bytes line(cut.begin(), cut.begin() + 10);
  append(line, encode(HeartbeatFrame{77}, 1));
  append(line, encode(HeartbeatFrame{78}, 2));
  FrameParser parser(Protocol::kBeaconloc);
  std::vector<Frame> out;
  parser.push(line.data(), line.size(), 0, out);
  ASSERT_EQ(out.size(), 2u);
  EXPECT_EQ(std::get<HeartbeatFrame>(out[0].body).stamp_us, 77u);
  EXPECT_EQ(std::get<HeartbeatFrame>(out[1].body).stamp_us, 78u);
  EXPECT_EQ(rejected(parser, FrameRejection::kBadChecksum), 1u);
  EXPECT_EQ(rejected(parser, FrameRejection::kGarbage), 0u);
  EXPECT_EQ(parser.counts().garbage_bytes, 10u);
}

// The same inside a Marvelmind packet whose bytes were damaged in transit.
TEST(SerialFrameResync, AGoodMarvelmindPacketBeginningInsideACorruptedOneIsFound) {
  DistancesFrame inner;
  inner.stamp_ms = 5;
  inner.hedge_address = 3;
  inner.slots = {{4, 4000}};
  Bytes outer = encode_marvelmind_distances(DistancesFrame{});
  const Bytes good = encode_marvelmind_distances(inner);
  Bytes line(outer.begin(), outer.begin() + 8);  // the outer packet loses its last 31 bytes
  append(line, good);
  FrameParser parser(Protocol::kMarvelmind);
  std::vector<Frame> out;
  parser.push(line.data(), line.size(), 0, out);
  ASSERT_EQ(out.size(), 1u);
  EXPECT_TRUE(std::get<DistancesFrame>(out[0].body) == inner);
  EXPECT_EQ(rejected(parser, FrameRejection::kBadChecksum), 1u);
  EXPECT_EQ(parser.counts().garbage_bytes, 8u);
}

// Two reads, cut at every byte; three reads, cut at every pair of bytes; a byte a read: the same
// frames, the same counts, the same bytes held.
TEST(SerialFrameResync, EverySplitIntoReadsGivesTheSameFramesAndCounts) {
  for (Protocol protocol : {Protocol::kBeaconloc, Protocol::kMarvelmind}) {
    SCOPED_TRACE(protocol == Protocol::kBeaconloc ? "beaconloc" : "marvelmind");
    const Bytes line = protocol == Protocol::kBeaconloc ? beaconloc_line() : marvelmind_line();
    const Outcome whole = parse_cut(protocol, line, {});
    for (std::size_t i = 0; i <= line.size(); ++i) {
      ASSERT_TRUE(same(parse_cut(protocol, line, {i}), whole)) << "cut at " << i;
      for (std::size_t j = i; j <= line.size(); j += 1) {
        ASSERT_TRUE(same(parse_cut(protocol, line, {i, j}), whole)) << "cuts at " << i << ", " << j;
      }
    }
    std::vector<std::size_t> every;
    for (std::size_t i = 1; i < line.size(); ++i) every.push_back(i);
    EXPECT_TRUE(same(parse_cut(protocol, line, every), whole));
  }
}

// What the lines above hold, counted: each fault once under its reason.
TEST(SerialFrameResync, EachFaultOfTheLineIsCountedOnceUnderItsReason) {
  const Outcome b = parse_cut(Protocol::kBeaconloc, beaconloc_line(), {});
  EXPECT_EQ(b.frames.size(), 6u);
  EXPECT_EQ(b.counts.rejections(FrameRejection::kBadChecksum), 2u);  // the corrupted and the cut TOF
  EXPECT_EQ(b.counts.rejections(FrameRejection::kBadLength), 1u);
  EXPECT_EQ(b.counts.rejections(FrameRejection::kUnknownVersion), 1u);
  EXPECT_EQ(b.counts.rejections(FrameRejection::kGarbage), 2u);  // the leading bytes, and 01 02
  EXPECT_EQ(b.counts.frames_lost, 1u + 1u + 3u);                 // sequences 1, 4, and 6 to 8
  EXPECT_EQ(b.pending, 3u);
  const Outcome m = parse_cut(Protocol::kMarvelmind, marvelmind_line(), {});
  EXPECT_EQ(m.frames.size(), 2u);
  EXPECT_EQ(m.counts.unused_frames, 1u);
  EXPECT_EQ(m.counts.rejections(FrameRejection::kBadChecksum), 2u);
  EXPECT_EQ(m.counts.rejections(FrameRejection::kBadLength), 1u);
  EXPECT_EQ(m.counts.rejections(FrameRejection::kGarbage), 1u);
  EXPECT_EQ(m.pending, 3u);
}

// Every byte pushed is in a checksum-verified frame, counted garbage, or held: none vanishes.
TEST(SerialFrameResync, EveryByteIsInAFrameCountedAsGarbageOrHeld) {
  const Outcome b = parse_cut(Protocol::kBeaconloc, beaconloc_line(), {});
  const std::uint64_t b_framed = 4 * 12 + 24 + 24;  // four heartbeats, a TOF, odometry
  EXPECT_EQ(b.counts.bytes, b_framed + b.counts.garbage_bytes + b.pending);
  const Outcome m = parse_cut(Protocol::kMarvelmind, marvelmind_line(), {});
  const std::uint64_t m_framed = 2 * 39 + 29;  // two distances packets, a position
  EXPECT_EQ(m.counts.bytes, m_framed + m.counts.garbage_bytes + m.pending);
}

// Bounded memory: a line that keeps announcing frames never makes the parser hold more than one.
TEST(SerialFrameResync, TheParserHoldsAtMostOneMaximumSizeFrame) {
  for (Protocol protocol : {Protocol::kBeaconloc, Protocol::kMarvelmind}) {
    FrameParser parser(protocol);
    const Bytes announce = protocol == Protocol::kBeaconloc ? Bytes{0xB7, 0x4C, 0x01, 0x01, 0x00, 0x10}
                                                            : Bytes{0xFF, 0x47, 0x09, 0x00, 0xFF};
    std::vector<Frame> out;
    for (int i = 0; i < 2000; ++i) {
      parser.push(announce.data(), announce.size(), i, out);
      ASSERT_LE(parser.pending_bytes(), FrameParser::max_frame_bytes(protocol));
    }
    EXPECT_TRUE(out.empty());
  }
  EXPECT_EQ(FrameParser::max_frame_bytes(Protocol::kBeaconloc), 24u);
  EXPECT_EQ(FrameParser::max_frame_bytes(Protocol::kMarvelmind), 262u);
}

}  // namespace
}  // namespace beaconloc::serial
