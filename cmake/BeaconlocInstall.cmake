# What `cmake --install` installs, and the Debian packages CPack makes of it (docs/deployment.md):
#   beaconloc (component runtime): the executable, the QoS profiles, the systemd units (deploy/),
#     the directory estimator plugins are installed into, the deployment key script
#   beaconloc-dev (component development): the SDK headers, libbeaconloc_sdk.a and the CMake package
#     (find_package(beaconloc) -> beaconloc::sdk, beaconloc_add_estimator_plugin)
include(CMakePackageConfigHelpers)

# Installed estimator plugins: `localizer --estimator-plugin <this directory>` loads each of them.
set(BEACONLOC_PLUGIN_INSTALL_DIR ${CMAKE_INSTALL_LIBDIR}/beaconloc/estimators)

install(TARGETS beaconloc RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR} COMPONENT runtime)
# The profiles are embedded in the executable; these copies are its reference, to read and to
# edit into a file given with --qos.
# The profiles that reach other hosts (network.xml, the discovery server's and its clients') are
# not embedded: a robot's configuration names them (--qos FILE --participant-profile NAME).
install(FILES examples/qos/loopback.xml examples/qos/topics.xml examples/qos/ros2_topics.xml examples/qos/network.xml
              examples/qos/discovery_client.xml examples/qos/discovery_server.xml
        DESTINATION ${CMAKE_INSTALL_DATADIR}/beaconloc/qos COMPONENT runtime)
install(PROGRAMS scripts/deployment-keys.sh DESTINATION ${CMAKE_INSTALL_DATADIR}/beaconloc COMPONENT runtime)
install(DIRECTORY DESTINATION ${BEACONLOC_PLUGIN_INSTALL_DIR} COMPONENT runtime)

set(config_dir ${CMAKE_INSTALL_LIBDIR}/cmake/beaconloc)
install(EXPORT beaconlocTargets NAMESPACE beaconloc:: DESTINATION ${config_dir} COMPONENT development)
configure_package_config_file(cmake/beaconlocConfig.cmake.in ${CMAKE_CURRENT_BINARY_DIR}/beaconlocConfig.cmake
                              INSTALL_DESTINATION ${config_dir} PATH_VARS BEACONLOC_PLUGIN_INSTALL_DIR)
# 0.x: the estimator API may change with every minor release (core/estimator_plugin.hpp's ABI).
write_basic_package_version_file(${CMAKE_CURRENT_BINARY_DIR}/beaconlocConfigVersion.cmake
                                 COMPATIBILITY SameMinorVersion)
install(FILES ${CMAKE_CURRENT_BINARY_DIR}/beaconlocConfig.cmake ${CMAKE_CURRENT_BINARY_DIR}/beaconlocConfigVersion.cmake
              cmake/beaconlocPlugin.cmake
        DESTINATION ${config_dir} COMPONENT development)

# Debian packages: cpack -G DEB in the build directory (scripts/package.sh).
set(CPACK_GENERATOR DEB)
set(CPACK_PACKAGE_NAME beaconloc)
set(CPACK_PACKAGE_VERSION ${PROJECT_VERSION})
set(CPACK_PACKAGE_CONTACT "beaconloc maintainers <maintainers@beaconloc.invalid>")
set(CPACK_PACKAGE_DESCRIPTION_SUMMARY "localization of mobile robots against ultrasonic ceiling beacons, over DDS")
# The package's files under /usr: installed with CMAKE_INSTALL_PREFIX=/usr into a DESTDIR, since
# the systemd units name the binary by the prefix they are installed with (deploy/CMakeLists.txt),
# which must be /usr, not CPack's staging directory. A build configured for /usr (scripts/build.sh
# Release) also gets Debian's multiarch library directory (lib/x86_64-linux-gnu) from GNUInstallDirs.
set(CPACK_PACKAGING_INSTALL_PREFIX /usr)
set(CPACK_INSTALL_PREFIX /usr)
set(CPACK_SET_DESTDIR ON)
set(CPACK_DEB_COMPONENT_INSTALL ON)
set(CPACK_COMPONENTS_ALL runtime development)
set(CPACK_DEBIAN_FILE_NAME DEB-DEFAULT)
set(CPACK_DEBIAN_PACKAGE_SECTION misc)
set(CPACK_DEBIAN_RUNTIME_PACKAGE_NAME beaconloc)
set(CPACK_DEBIAN_RUNTIME_PACKAGE_SECTION misc)
# The shared libraries' packages (Fast DDS, Fast CDR, yaml-cpp, OpenSSL, sqlite3, tinyxml2, libstdc++)
# found by dpkg-shlibdeps from the executable itself, so they are never listed by hand.
set(CPACK_DEBIAN_RUNTIME_PACKAGE_SHLIBDEPS ON)
# share/beaconloc/deployment-keys.sh makes a secured deployment's keys with the openssl tool.
set(CPACK_DEBIAN_RUNTIME_PACKAGE_RECOMMENDS openssl)
set(CPACK_DEBIAN_DEVELOPMENT_PACKAGE_NAME beaconloc-dev)
set(CPACK_DEBIAN_DEVELOPMENT_PACKAGE_SECTION libdevel)
# What building a plugin needs beside the SDK: its headers' dependencies and the tools.
set(CPACK_DEBIAN_DEVELOPMENT_PACKAGE_DEPENDS
    "beaconloc (= ${PROJECT_VERSION}), libeigen3-dev (>= 3.3), libyaml-cpp-dev, cmake (>= 3.22), g++")
# The maintainer scripts: the system user, systemd reloaded, participants stopped on removal.
set(CPACK_DEBIAN_RUNTIME_PACKAGE_CONTROL_EXTRA ${PROJECT_SOURCE_DIR}/deploy/debian/postinst
    ${PROJECT_SOURCE_DIR}/deploy/debian/prerm ${PROJECT_SOURCE_DIR}/deploy/debian/postrm)
set(CPACK_DEBIAN_RUNTIME_PACKAGE_CONTROL_STRICT_PERMISSION ON)
include(CPack)
