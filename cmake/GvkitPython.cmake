# The Python module (python/): finds the interpreter and pybind11 and adds python/. The
# interpreter is Debian's /usr/bin/python3 when it exists (where apt installs numpy and
# matplotlib), not whichever python3 comes first on PATH; set Python_EXECUTABLE to choose another.
# Without pybind11 the module is skipped with a message (scripts/setup installs it).
if(NOT DEFINED Python_EXECUTABLE AND EXISTS /usr/bin/python3)
  set(Python_EXECUTABLE /usr/bin/python3 CACHE FILEPATH "Python interpreter of the gvkit module")
endif()
set(PYBIND11_FINDPYTHON ON)
find_package(Python 3.9 COMPONENTS Interpreter Development.Module)
find_package(pybind11 2.6 CONFIG QUIET)
if(Python_FOUND AND pybind11_FOUND)
  add_subdirectory(python)
else()
  message(WARNING "gvkit: Python module skipped (needs python3-dev and pybind11-dev: "
                  "scripts/setup installs them)")
endif()
