# beaconloc_embed_text(<output.cpp> <c++ symbol> <file>)
# Embeds a text file (the QoS profiles) into the binary as a std::string_view, so `beaconloc`
# works from any directory while the XML in the repo stays the one source of truth.
function(beaconloc_embed_text output symbol input)
  add_custom_command(
    OUTPUT ${output}
    COMMAND ${CMAKE_COMMAND} -DINPUT=${input} -DOUTPUT=${output} -DSYMBOL=${symbol}
            -P ${PROJECT_SOURCE_DIR}/cmake/EmbedTextScript.cmake
    DEPENDS ${input} ${PROJECT_SOURCE_DIR}/cmake/EmbedTextScript.cmake
    COMMENT "embedding ${input}"
    VERBATIM)
endfunction()
