# Finds what the Python module needs: an interpreter that has NumPy (the one
# the module is built for, tested with and installed for) and pybind11.
# Sets IMUSYSID_PYTHON_FOUND. Python_EXECUTABLE, when given, is used as it
# is; otherwise the first of `python3` on PATH and /usr/bin/python3 that can
# import numpy (a python3 of a version manager may come first on PATH
# without the Debian packages the module and its tests use).
set(IMUSYSID_PYTHON_FOUND OFF)
if(NOT Python_EXECUTABLE)
  find_program(IMUSYSID_PATH_PYTHON3 python3)
  foreach(candidate ${IMUSYSID_PATH_PYTHON3} /usr/bin/python3)
    if(NOT EXISTS "${candidate}")
      continue()
    endif()
    execute_process(
      COMMAND "${candidate}" -c "import numpy, sys; print(sys.executable)"
      OUTPUT_VARIABLE resolved OUTPUT_STRIP_TRAILING_WHITESPACE
      RESULT_VARIABLE rc ERROR_QUIET)
    if(rc EQUAL 0 AND resolved)
      set(Python_EXECUTABLE "${resolved}" CACHE FILEPATH
          "The Python the imusysid module is built for")
      break()
    endif()
  endforeach()
endif()
if(Python_EXECUTABLE)
  find_package(Python 3.8 COMPONENTS Interpreter Development.Module QUIET)
  if(Python_FOUND)
    set(PYBIND11_FINDPYTHON ON)
    find_package(pybind11 2.6 CONFIG QUIET)
    if(pybind11_FOUND)
      set(IMUSYSID_PYTHON_FOUND ON)
    endif()
    # Where the package is installed, relative to the prefix: Python's own
    # folder there (Debian's dist-packages, which /usr/bin/python3 reads
    # under /usr/local; site-packages elsewhere).
    execute_process(
      COMMAND "${Python_EXECUTABLE}" -c
              "import sys; print('dist-packages' if any(p.endswith('dist-packages') for p in sys.path) else 'site-packages')"
      OUTPUT_VARIABLE imusysid_site_name OUTPUT_STRIP_TRAILING_WHITESPACE)
    set(IMUSYSID_PYTHON_INSTALL_DIR
        "${CMAKE_INSTALL_LIBDIR}/python${Python_VERSION_MAJOR}.${Python_VERSION_MINOR}/${imusysid_site_name}"
        CACHE STRING "Where the Python package is installed, relative to the prefix")
  endif()
endif()
if(NOT IMUSYSID_PYTHON_FOUND)
  message(STATUS "imusysid: no pybind11 or no Python with NumPy; the Python "
                 "module is not built (scripts/setup.sh installs them)")
endif()
