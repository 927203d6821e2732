# beaconloc_add_estimator_plugin(<target> <source>...): an estimator plugin the localizer loads at
# run time (--estimator-plugin FILE or DIR; beaconloc/core/estimator_plugin.hpp): a shared library
# (MODULE) holding the estimators its sources register and BEACONLOC_ESTIMATOR_PLUGIN() once. It
# links its own copy of the SDK (beaconloc::sdk) with every symbol of it hidden (--exclude-libs) and
# its own code hidden by default: it exports nothing but its two entry points, so that it never binds
# to the localizer's copy of the SDK, nor the localizer to its. Installed with the SDK and used by
# the tests' own plugins, so in-tree and out-of-tree plugins are built the same way.
function(beaconloc_add_estimator_plugin target)
  if(NOT ARGN)
    message(FATAL_ERROR "beaconloc_add_estimator_plugin(${target}): no source files")
  endif()
  add_library(${target} MODULE ${ARGN})
  target_link_libraries(${target} PRIVATE beaconloc::sdk)
  target_compile_features(${target} PRIVATE cxx_std_17)
  set_target_properties(${target} PROPERTIES CXX_VISIBILITY_PRESET hidden VISIBILITY_INLINES_HIDDEN ON PREFIX "lib"
                                             SUFFIX ".so")
  target_link_options(${target} PRIVATE "LINKER:--exclude-libs,ALL")
endfunction()
