# Included from plugins/CMakeLists.txt: paths are relative to plugins/.
# The serial line to receiver modules (DDS-free): framing and checksums of both protocols
# (docs/serial-protocol.md), the device clock's mapping to the host's, termios.
add_library(beaconloc_serial STATIC
  gateway/serial/frame_rejection.cpp
  gateway/serial/crc16.cpp
  gateway/serial/frame_encoder.cpp
  gateway/serial/frame_parser.cpp
  gateway/serial/device_clock.cpp
  gateway/serial/serial_port.cpp)
target_include_directories(beaconloc_serial PUBLIC gateway/serial)
target_link_libraries(beaconloc_serial PUBLIC beaconloc_core PRIVATE beaconloc_warnings)

# The gateway's source on a serial line (frames -> the bus's samples), on top of the above.
add_library(beaconloc_serial_source STATIC gateway/serial/serial_source.cpp gateway/serial/line_simulator.cpp)
target_link_libraries(beaconloc_serial_source PUBLIC beaconloc_serial beaconloc_sim PRIVATE beaconloc_warnings)
