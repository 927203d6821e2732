# Estimator plugins (localizer/estimator_plugins.hpp) and configuration files (cli/config_file.hpp):
# the example plugin of examples/estimator_plugin built in tree (so that every build, the sanitized
# one included, compiles and loads it) and plugins each refused for one reason.
beaconloc_add_estimator_plugin(beaconloc_test_example_plugin
  ${PROJECT_SOURCE_DIR}/examples/estimator_plugin/placed_range_ekf.cpp)
beaconloc_add_estimator_plugin(beaconloc_test_old_sdk_plugin ${CMAKE_CURRENT_LIST_DIR}/old_sdk_plugin.cpp)
beaconloc_add_estimator_plugin(beaconloc_test_duplicate_plugin ${CMAKE_CURRENT_LIST_DIR}/duplicate_plugin.cpp)
beaconloc_add_estimator_plugin(beaconloc_test_empty_plugin ${CMAKE_CURRENT_LIST_DIR}/empty_plugin.cpp)
add_library(beaconloc_test_not_a_plugin MODULE ${CMAKE_CURRENT_LIST_DIR}/not_a_plugin.cpp)

add_executable(beaconloc_plugin_tests ${CMAKE_CURRENT_LIST_DIR}/estimator_plugins_test.cpp
  ${CMAKE_CURRENT_LIST_DIR}/config_file_test.cpp ${PROJECT_SOURCE_DIR}/plugins/cli/config_file.cpp)
target_include_directories(beaconloc_plugin_tests PRIVATE ${PROJECT_SOURCE_DIR}/plugins/cli
  ${PROJECT_SOURCE_DIR}/tests/support)
target_link_libraries(beaconloc_plugin_tests PRIVATE beaconloc_estimators beaconloc_offline CLI11::CLI11 yaml-cpp
  GTest::gtest_main beaconloc_warnings)
add_dependencies(beaconloc_plugin_tests beaconloc_test_example_plugin beaconloc_test_old_sdk_plugin
  beaconloc_test_duplicate_plugin beaconloc_test_empty_plugin beaconloc_test_not_a_plugin)
target_compile_definitions(beaconloc_plugin_tests PRIVATE BEACONLOC_SOURCE_DIR="${PROJECT_SOURCE_DIR}"
  EXAMPLE_PLUGIN="$<TARGET_FILE:beaconloc_test_example_plugin>"
  OLD_SDK_PLUGIN="$<TARGET_FILE:beaconloc_test_old_sdk_plugin>"
  DUPLICATE_PLUGIN="$<TARGET_FILE:beaconloc_test_duplicate_plugin>"
  EMPTY_PLUGIN="$<TARGET_FILE:beaconloc_test_empty_plugin>"
  NOT_A_PLUGIN="$<TARGET_FILE:beaconloc_test_not_a_plugin>")
gtest_discover_tests(beaconloc_plugin_tests TEST_PREFIX "unit." DISCOVERY_TIMEOUT 30)

# The acceptance test of deployment (Release only, scripts/test.sh): the Debian packages made by
# CPack, unpacked into a fresh prefix; the example plugin built against that SDK out of tree; a
# pipeline run with it from a configuration file.
add_test(NAME integration.StagedInstall
  COMMAND bash ${PROJECT_SOURCE_DIR}/tests/tools/staged_install_test.sh ${PROJECT_SOURCE_DIR} ${CMAKE_BINARY_DIR})
set_tests_properties(integration.StagedInstall PROPERTIES TIMEOUT 600)
