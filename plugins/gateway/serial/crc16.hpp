#pragma once
// The two 16-bit CRCs of the serial line (docs/serial-protocol.md), bit by bit: a frame is at
// most 262 bytes, so a table buys nothing worth its 512 bytes here.
#include <cstddef>
#include <cstdint>

namespace beaconloc::serial {

// CRC-16/CCITT-FALSE: poly 0x1021, init 0xFFFF, not reflected, xorout 0; "123456789" -> 0x29B1.
// The beaconloc protocol's checksum.
std::uint16_t crc16_ccitt_false(const std::uint8_t* data, std::size_t size);

// CRC-16/MODBUS: reflected poly 0xA001, init 0xFFFF, xorout 0; "123456789" -> 0x4B37. Marvelmind's
// checksum; sent low byte first, so the CRC over a whole packet, checksum included, is 0.
std::uint16_t crc16_modbus(const std::uint8_t* data, std::size_t size);

}  // namespace beaconloc::serial
