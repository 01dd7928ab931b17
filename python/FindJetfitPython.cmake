# Finds the interpreter the Python module is built for: Python3_EXECUTABLE
# if the user gave one, else the first of `python3` on PATH and the
# system's /usr/bin/python3 that can import numpy (a pyenv or venv python3
# first on PATH often has no NumPy while the distribution's has).  Sets
# JF_PYTHON_FOUND, and the Python3:: targets through FindPython3.
set(JF_PYTHON_FOUND OFF)
if(NOT Python3_EXECUTABLE)
  find_program(JF_PY_ON_PATH NAMES python3)
  foreach(py ${JF_PY_ON_PATH} /usr/bin/python3)
    if(EXISTS "${py}")
      execute_process(COMMAND "${py}" -c "import numpy" RESULT_VARIABLE r
                      OUTPUT_QUIET ERROR_QUIET)
      if(r EQUAL 0)
        set(Python3_EXECUTABLE "${py}" CACHE FILEPATH "Python for the jetfit module")
        break()
      endif()
    endif()
  endforeach()
endif()
if(Python3_EXECUTABLE)
  find_package(Python3 QUIET COMPONENTS Interpreter Development.Module NumPy)
  if(Python3_FOUND AND Python3_NumPy_FOUND AND Python3_Development.Module_FOUND)
    set(JF_PYTHON_FOUND ON)
  endif()
endif()
