# SPDX-License-Identifier: MIT
# The Python module's prerequisites (engine/python): an interpreter with its headers, and pybind11
# (Debian: python3-dev, pybind11-dev; numpy, pytest and matplotlib at run time: python3-numpy,
# python3-pytest, python3-matplotlib). Without pybind11 the module is skipped with a note.
# The interpreter: Python_EXECUTABLE when given; else the first python3 of PATH that imports
# numpy, else /usr/bin/python3 when it does (the one apt's python3-* packages serve: a pyenv or
# venv python3 earlier on PATH would build a module its numpy-less interpreter cannot test).
set(VKCLOTH_PYTHON_FOUND OFF)
if(NOT Python_EXECUTABLE)
  find_program(vkcloth_path_python3 NAMES python3 NO_CACHE)
  foreach(candidate IN ITEMS ${vkcloth_path_python3} /usr/bin/python3)
    if(EXISTS ${candidate})
      execute_process(COMMAND ${candidate} -c "import numpy" RESULT_VARIABLE vkcloth_numpy_rc
                      OUTPUT_QUIET ERROR_QUIET)
      if(vkcloth_numpy_rc EQUAL 0)
        set(Python_EXECUTABLE ${candidate} CACHE FILEPATH "The Python interpreter the module is built for")
        break()
      endif()
    endif()
  endforeach()
endif()
find_package(Python 3.8 COMPONENTS Interpreter Development.Module)
if(Python_FOUND)
  set(PYBIND11_FINDPYTHON ON) # pybind11 takes the Python found above
  find_package(pybind11 CONFIG QUIET)
endif()
if(Python_FOUND AND pybind11_FOUND)
  set(VKCLOTH_PYTHON_FOUND ON)
  message(STATUS "vkcloth: the Python module for ${Python_EXECUTABLE} (${Python_VERSION}), pybind11 ${pybind11_VERSION}")
else()
  message(STATUS "vkcloth: no Python module (needs python3-dev and pybind11-dev; VKCLOTH_BUILD_PYTHON=OFF silences this)")
endif()
