# SPDX-License-Identifier: MIT
# Fails unless README (README.md, or the page given) contains, verbatim (indentation removed), the
# lines of SOURCE between "// [MARKER]" and "// [/MARKER]" (MARKER: quickstart unless given;
# KEEP_INDENT: compare the lines as they are).
if(NOT MARKER)
  set(MARKER quickstart)
endif()
file(READ ${SOURCE} source)
string(REGEX MATCH "// \\[${MARKER}\\]\n(.*)\n[ ]*// \\[/${MARKER}\\]" _ "${source}")
set(snippet "${CMAKE_MATCH_1}")
if(snippet STREQUAL "")
  message(FATAL_ERROR "${SOURCE}: no // [${MARKER}] ... // [/${MARKER}] block")
endif()
if(NOT KEEP_INDENT) # the quick start's lines sit inside main(); the page shows them unindented
  string(REGEX REPLACE "(^|\n)  " "\\1" snippet "${snippet}")
endif()
file(READ ${README} readme)
string(FIND "${readme}" "${snippet}" at)
if(at EQUAL -1)
  message(FATAL_ERROR "${README} does not show the ${MARKER} lines of ${SOURCE} verbatim; paste these "
                      "lines into its C++ block:\n${snippet}")
endif()
