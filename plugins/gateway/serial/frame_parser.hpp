#pragma once
// The serial line's streaming parser (docs/serial-protocol.md): bytes in as the line delivers
// them, frames out. Bad input is counted by reason, never thrown; nothing is repaired.
//
// Resynchronization: bytes before a sync are garbage. A candidate frame whose header is refused
// (unknown version or type, a length its type does not have) is refused at once, without waiting
// for the bytes its length announces; one whose checksum fails is refused when its bytes are in.
// Either way the search starts again at the byte after its first sync byte, so a frame that begins
// inside a refused one is still found. The result depends on the bytes only, never on how the
// reads cut them, and the parser keeps at most one maximum-size frame of bytes.
#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "beaconloc/core/time.hpp"
#include "frame_rejection.hpp"
#include "frames.hpp"
#include "wire_format.hpp"

namespace beaconloc::serial {

class FrameParser {
 public:
  struct Counts {
    std::uint64_t bytes = 0;          // pushed
    std::uint64_t frames = 0;         // yielded
    std::uint64_t unused_frames = 0;  // checksum good, a Marvelmind packet other than raw distances
    std::uint64_t garbage_bytes = 0;  // every byte not part of a checksum-verified frame
    std::uint64_t frames_lost = 0;    // beaconloc sequence numbers skipped
    std::array<std::uint64_t, kFrameRejectionCount> rejected{};  // by FrameRejection

    std::uint64_t rejections(FrameRejection r) const { return rejected[static_cast<std::size_t>(r)]; }
  };

  // The most bytes a frame of the protocol can take: what the parser may hold.
  static constexpr std::size_t max_frame_bytes(Protocol protocol) {
    return protocol == Protocol::kBeaconloc ? wire::kBeaconlocMaxFrameBytes : wire::kMarvelmindMaxFrameBytes;
  }

  explicit FrameParser(Protocol protocol);

  // Bytes as read from the line, with the host time of that read: a frame's arrival is the read
  // that completed it. Frames are appended to `out`.
  void push(const std::uint8_t* data, std::size_t size, StampNs arrival_ns, std::vector<Frame>& out);

  // The line went away (the port reports it gone) or is reopened: a frame begun is dropped and
  // counted kTruncated (its bytes as garbage bytes), and the sequence numbering starts afresh (a
  // gap across a reopen is the line's absence, not frames lost in transmission).
  void reset_partial();

  const Counts& counts() const { return counts_; }
  Protocol protocol() const { return protocol_; }
  // Bytes held for a frame not yet complete (at most max_frame_bytes(protocol())).
  std::size_t pending_bytes() const { return pending_; }

 private:
  // What the header of the candidate at the front says.
  struct HeaderVerdict {
    bool refused = false;
    FrameRejection reason = FrameRejection::kBadLength;
    std::size_t frame_bytes = 0;  // header, payload and checksum, when not refused
  };

  void scan(StampNs arrival_ns, std::vector<Frame>& out);
  bool is_second_sync_byte(std::uint8_t byte) const;
  HeaderVerdict judge_header(const std::uint8_t* frame) const;
  bool checksum_ok(const std::uint8_t* frame, std::size_t frame_bytes) const;
  void accept_beaconloc(const std::uint8_t* frame, StampNs arrival_ns, std::vector<Frame>& out);
  void accept_marvelmind(const std::uint8_t* frame, StampNs arrival_ns, std::vector<Frame>& out);
  void skip_garbage(std::size_t bytes);
  void refuse(FrameRejection reason);

  Protocol protocol_;
  std::size_t header_bytes_;
  std::size_t capacity_;
  std::array<std::uint8_t, wire::kMarvelmindMaxFrameBytes> buffer_{};
  std::size_t pending_ = 0;
  // Skipping bytes already: a garbage run counted, or the tail of a refused frame (that refusal's).
  bool skipping_ = false;
  bool have_sequence_ = false;
  std::uint8_t last_sequence_ = 0;
  Counts counts_;
};

}  // namespace beaconloc::serial
