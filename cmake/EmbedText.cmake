# Writes the text file INPUT into the C++ header OUTPUT as `inline constexpr std::string_view NAME`.
# Run with cmake -DINPUT=... -DOUTPUT=... -DNAME=... -P EmbedText.cmake
file(READ "${INPUT}" content)
string(FIND "${content}" ")fignet_embedded\"" clash)
if(NOT clash EQUAL -1)
  message(FATAL_ERROR "${INPUT} contains the raw-string delimiter used to embed it")
endif()
file(WRITE "${OUTPUT}.tmp" "// Generated from ${INPUT} by cmake/EmbedText.cmake: do not edit.
#pragma once
#include <string_view>
inline constexpr char ${NAME}Text[] = R\"fignet_embedded(${content})fignet_embedded\";
inline constexpr std::string_view ${NAME}(${NAME}Text, sizeof(${NAME}Text) - 1);
")
file(RENAME "${OUTPUT}.tmp" "${OUTPUT}")
