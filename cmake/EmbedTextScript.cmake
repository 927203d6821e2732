file(READ ${INPUT} content)
string(FIND "${content}" ")BEACONLOC_EMBED\"" clash)
if(NOT clash EQUAL -1)
  message(FATAL_ERROR "${INPUT} contains the raw-string delimiter")
endif()
file(WRITE ${OUTPUT}
  "// Generated from ${INPUT}; do not edit.\n#include <string_view>\n"
  "namespace beaconloc::embedded {\n"
  "extern const std::string_view ${SYMBOL};\n"
  "const std::string_view ${SYMBOL} = R\"BEACONLOC_EMBED(${content})BEACONLOC_EMBED\";\n}\n")
