# Included from tests/CMakeLists.txt: paths are relative to tests/.
# The serial line (plugins/gateway/serial, docs/serial-protocol.md): both protocols' parser and
# encoders, the device clock, and the termios port on pseudo-terminals (openpty: libutil).
add_executable(beaconloc_serial_tests
  unit/serial/crc16_test.cpp
  unit/serial/frame_parser_test.cpp
  unit/serial/frame_resync_test.cpp
  unit/serial/marvelmind_test.cpp
  unit/serial/parser_fuzz_test.cpp
  unit/serial/device_clock_test.cpp
  unit/serial/serial_port_test.cpp
  unit/serial/serial_source_test.cpp)
target_link_libraries(beaconloc_serial_tests PRIVATE beaconloc_serial beaconloc_serial_source GTest::gtest_main util beaconloc_warnings)
gtest_discover_tests(beaconloc_serial_tests TEST_PREFIX "unit." DISCOVERY_TIMEOUT 30)
