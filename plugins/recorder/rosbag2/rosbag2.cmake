# Included from plugins/CMakeLists.txt: paths are relative to plugins/.
# rosbag2 bags (sqlite3 storage) written from serialized CDR messages: no ROS 2, no DDS.
find_package(SQLite3 REQUIRED)
add_library(beaconloc_rosbag2 STATIC recorder/rosbag2/rosbag2_writer.cpp)
target_include_directories(beaconloc_rosbag2 PUBLIC recorder/rosbag2)
target_link_libraries(beaconloc_rosbag2 PRIVATE SQLite::SQLite3 beaconloc_core beaconloc_warnings)
