# Fails when a file of the DDS-free core includes a DDS header: the SDK core, the estimators,
# the decoder and localizer cores (with the shards' and conflicts' bookkeeping), the monitor's
# pose tally and fleet view, the evaluation, and the simulator.
file(GLOB_RECURSE files
  ${ROOT}/plugins/sdk/include/beaconloc/core/*
  ${ROOT}/plugins/sdk/src/*
  ${ROOT}/plugins/localizer/estimators/*
  ${ROOT}/plugins/localizer/localizer_core.*
  ${ROOT}/plugins/localizer/shard_membership.*
  ${ROOT}/plugins/localizer/serving_conflicts.*
  ${ROOT}/plugins/recorder/pose_tally.*
  ${ROOT}/plugins/eval/*
  ${ROOT}/plugins/cli/fleet_view.*
  ${ROOT}/plugins/decoder/tof_decoder.*
  ${ROOT}/plugins/gateway/sim/*)
list(LENGTH files count)
if(count LESS 10)
  message(FATAL_ERROR "expected the core's files under ${ROOT}, found ${count}")
endif()
foreach(f ${files})
  file(STRINGS ${f} hits REGEX "#[ \t]*include[ \t]*[<\"](fastdds|fastrtps|fastcdr|beaconloc\\.h|beaconlocPubSubTypes|beaconloc/dds)")
  if(hits)
    message(FATAL_ERROR "${f} includes a DDS header: ${hits}")
  endif()
endforeach()
message(STATUS "${count} core files, none includes a DDS header")
