# Included from tests/CMakeLists.txt: paths are relative to tests/.
# The rosbag2 writer (plugins/recorder/rosbag2), read back with the sqlite3 C API, yaml-cpp and the
# independent reader tests/tools/check_rosbag2.py (run from the tests: it needs python3-yaml,
# which the system python has and the PATH's pyenv python lacks).
find_package(SQLite3 REQUIRED)
find_program(BEACONLOC_SYSTEM_PYTHON3 NAMES python3 PATHS /usr/bin NO_DEFAULT_PATH REQUIRED)
add_executable(beaconloc_rosbag2_tests unit/rosbag2/rosbag2_writer_test.cpp)
target_link_libraries(beaconloc_rosbag2_tests PRIVATE beaconloc_rosbag2 SQLite::SQLite3 yaml-cpp GTest::gtest_main
  beaconloc_warnings)
target_compile_definitions(beaconloc_rosbag2_tests PRIVATE BEACONLOC_SYSTEM_PYTHON3="${BEACONLOC_SYSTEM_PYTHON3}"
  BEACONLOC_CHECK_ROSBAG2="${PROJECT_SOURCE_DIR}/tests/tools/check_rosbag2.py")
gtest_discover_tests(beaconloc_rosbag2_tests TEST_PREFIX "unit." DISCOVERY_TIMEOUT 30)
