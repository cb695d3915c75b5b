# SPDX-License-Identifier: MIT
# Fails unless README.md contains, verbatim (indentation removed), the lines of SOURCE between
# "// [quickstart]" and "// [/quickstart]".
file(READ ${SOURCE} source)
string(REGEX MATCH "// \\[quickstart\\]\n(.*)\n[ ]*// \\[/quickstart\\]" _ "${source}")
set(snippet "${CMAKE_MATCH_1}")
if(snippet STREQUAL "")
  message(FATAL_ERROR "${SOURCE}: no // [quickstart] ... // [/quickstart] block")
endif()
string(REGEX REPLACE "(^|\n)  " "\\1" snippet "${snippet}")
file(READ ${README} readme)
string(FIND "${readme}" "${snippet}" at)
if(at EQUAL -1)
  message(FATAL_ERROR "README.md does not show the quick start of ${SOURCE} verbatim; paste these lines "
                      "into its C++ block:\n${snippet}")
endif()
