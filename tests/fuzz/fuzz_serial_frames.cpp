// Fuzz target: the serial line's frame parser (plugins/gateway/serial/frame_parser.cpp, both
// protocols, docs/serial-protocol.md). Input: a first byte choosing the protocol (bit 0) and how the
// rest arrives (its other bits: the size of the reads), then the line's bytes. Whatever the bytes,
// no crash, no undefined behaviour, no hang; the parser holds at most one frame's bytes; and how the
// bytes are cut into reads changes nothing: the same frames and the same counts as one read.
#include <cstddef>
#include <cstdint>
#include <vector>

#include "frame_parser.hpp"

namespace {

void check(bool ok) {
  if (!ok) __builtin_trap();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace beaconloc::serial;
  if (size < 1) return 0;
  const Protocol protocol = (data[0] & 1) ? Protocol::kMarvelmind : Protocol::kBeaconloc;
  const std::size_t read_size = 1 + (data[0] >> 1);  // 1..128 bytes per read
  const std::uint8_t* line = data + 1;
  const std::size_t length = size - 1;

  FrameParser whole(protocol), pieces(protocol);
  std::vector<Frame> all_at_once, in_reads;
  whole.push(line, length, 0, all_at_once);
  for (std::size_t at = 0; at < length; at += read_size) {
    const std::size_t n = at + read_size <= length ? read_size : length - at;
    pieces.push(line + at, n, 0, in_reads);
    check(pieces.pending_bytes() <= FrameParser::max_frame_bytes(protocol));
  }
  check(whole.pending_bytes() <= FrameParser::max_frame_bytes(protocol));
  check(in_reads == all_at_once);
  const FrameParser::Counts& a = whole.counts();
  const FrameParser::Counts& b = pieces.counts();
  check(a.frames == b.frames && a.unused_frames == b.unused_frames && a.frames_lost == b.frames_lost &&
        a.rejected == b.rejected && a.bytes == length && b.bytes == length);
  check(a.frames == all_at_once.size());
  return 0;
}
