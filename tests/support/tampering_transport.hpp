#pragma once
// A UDPv4 transport on loopback that, once told to, flips one byte in the middle of every
// secured RTPS message it sends (one whose first submessage is SRTPS_PREFIX: discovery
// announcements, which DDS Security leaves in the clear, go out intact). What a man in the middle
// on the wire would do to a participant's messages; for the security tests.
#include <fastdds/rtps/transport/ChainingTransport.h>
#include <fastdds/rtps/transport/ChainingTransportDescriptor.h>
#include <fastdds/rtps/transport/UDPv4TransportDescriptor.h>

#include <atomic>
#include <chrono>
#include <cstdint>
#include <memory>
#include <vector>

namespace beaconloc::testing {

struct TamperingSwitch {
  std::atomic<bool> on{false};
  std::atomic<std::uint64_t> tampered{0};  // messages sent with a byte flipped
};

class TamperingTransportDescriptor : public eprosima::fastdds::rtps::ChainingTransportDescriptor {
 public:
  explicit TamperingTransportDescriptor(std::shared_ptr<TamperingSwitch> tamper)
      : ChainingTransportDescriptor(loopback_udp()), tamper_(std::move(tamper)) {}
  eprosima::fastdds::rtps::TransportInterface* create_transport() const override;

 private:
  static std::shared_ptr<eprosima::fastdds::rtps::UDPv4TransportDescriptor> loopback_udp() {
    auto udp = std::make_shared<eprosima::fastdds::rtps::UDPv4TransportDescriptor>();
    udp->interfaceWhiteList.emplace_back("127.0.0.1");  // nothing leaves the machine
    return udp;
  }
  friend class TamperingTransport;
  std::shared_ptr<TamperingSwitch> tamper_;
};

class TamperingTransport : public eprosima::fastdds::rtps::ChainingTransport {
 public:
  explicit TamperingTransport(const TamperingTransportDescriptor& descriptor)
      : ChainingTransport(descriptor), configuration_(descriptor), tamper_(descriptor.tamper_) {}
  eprosima::fastdds::rtps::TransportDescriptorInterface* get_configuration() override {
    return &configuration_;
  }

  bool send(eprosima::fastrtps::rtps::SenderResource* low, const eprosima::fastrtps::rtps::octet* buffer,
            std::uint32_t size, eprosima::fastrtps::rtps::LocatorsIterator* begin,
            eprosima::fastrtps::rtps::LocatorsIterator* end,
            const std::chrono::steady_clock::time_point& timeout) override {
    constexpr std::uint32_t kRtpsHeaderBytes = 20;
    constexpr std::uint8_t kSrtpsPrefix = 0x33;
    constexpr std::uint32_t kSmallest = 128;  // past header, prefix and tag: the middle is the body
    if (!tamper_->on || size < kSmallest || buffer[kRtpsHeaderBytes] != kSrtpsPrefix) {
      return low->send(buffer, size, begin, end, timeout);
    }
    std::vector<eprosima::fastrtps::rtps::octet> copy(buffer, buffer + size);
    copy[size / 2] ^= 0x5a;
    ++tamper_->tampered;
    return low->send(copy.data(), size, begin, end, timeout);
  }
  void receive(eprosima::fastdds::rtps::TransportReceiverInterface* next,
               const eprosima::fastrtps::rtps::octet* buffer, std::uint32_t size,
               const eprosima::fastrtps::rtps::Locator_t& local,
               const eprosima::fastrtps::rtps::Locator_t& remote) override {
    next->OnDataReceived(buffer, size, local, remote);
  }

 private:
  TamperingTransportDescriptor configuration_;
  std::shared_ptr<TamperingSwitch> tamper_;
};

inline eprosima::fastdds::rtps::TransportInterface* TamperingTransportDescriptor::create_transport() const {
  return new TamperingTransport(*this);
}

}  // namespace beaconloc::testing
