# beaconloc_idl_library(<target> IDL <file.idl>... [ROS2])
# Runs fastddsgen at build time into the build tree and compiles the output into a static
# library. Generated code is never committed. ROS2 adds -typeros2 -cs (ROS 2 type names).
find_program(FASTDDSGEN_EXECUTABLE fastddsgen REQUIRED)

function(beaconloc_idl_library target)
  cmake_parse_arguments(ARG "ROS2" "" "IDL" ${ARGN})
  set(out_dir ${CMAKE_CURRENT_BINARY_DIR}/${target}_gen)
  file(MAKE_DIRECTORY ${out_dir})
  set(flags -replace -d ${out_dir})
  if(ARG_ROS2)
    list(APPEND flags -typeros2 -cs)
  endif()
  set(sources)
  foreach(idl ${ARG_IDL})
    get_filename_component(abs ${idl} ABSOLUTE)
    get_filename_component(stem ${idl} NAME_WE)
    set(outputs ${out_dir}/${stem}.h ${out_dir}/${stem}.cxx
                ${out_dir}/${stem}PubSubTypes.h ${out_dir}/${stem}PubSubTypes.cxx)
    get_filename_component(idl_dir ${abs} DIRECTORY)
    add_custom_command(
      OUTPUT ${outputs}
      COMMAND ${FASTDDSGEN_EXECUTABLE} ${flags} -I ${idl_dir} ${abs}
      DEPENDS ${ARG_IDL}
      COMMENT "fastddsgen ${stem}.idl"
      VERBATIM)
    list(APPEND sources ${out_dir}/${stem}.cxx ${out_dir}/${stem}PubSubTypes.cxx)
  endforeach()
  add_library(${target} STATIC ${sources})
  target_include_directories(${target} SYSTEM PUBLIC ${out_dir})
  target_link_libraries(${target} PUBLIC fastrtps fastcdr)
  set_target_properties(${target} PROPERTIES POSITION_INDEPENDENT_CODE ON)
endfunction()
