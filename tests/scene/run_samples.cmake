# SPDX-License-Identifier: MIT
# Runs every sample scene with `vkcloth run` (CPU, float and double); fails on a non-zero exit.
file(GLOB scenes "${SCENES}/*.json")
if(NOT scenes)
  message(FATAL_ERROR "no scenes in ${SCENES}")
endif()
foreach(scene IN LISTS scenes)
  foreach(precision float double)
    execute_process(COMMAND "${VKCLOTH}" run "${scene}" --precision ${precision}
                    RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
    if(NOT rc EQUAL 0)
      message(FATAL_ERROR "vkcloth run ${scene} --precision ${precision} exited ${rc}: ${err}")
    endif()
    message(STATUS "${out}")
  endforeach()
endforeach()
