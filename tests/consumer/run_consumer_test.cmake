# Installs the already-built project into a temporary prefix, then configures,
# builds and runs tests/consumer against it with find_package(imusysid).
file(REMOVE_RECURSE ${WORK_DIR})
file(MAKE_DIRECTORY ${WORK_DIR})
execute_process(COMMAND ${CMAKE_COMMAND} --install ${BUILD_DIR} --prefix ${WORK_DIR}/prefix
  RESULT_VARIABLE rc)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "install failed (${rc})")
endif()
execute_process(COMMAND ${CMAKE_COMMAND} -S ${SOURCE_DIR}/tests/consumer -B ${WORK_DIR}/build
  -DCMAKE_PREFIX_PATH=${WORK_DIR}/prefix -DCMAKE_BUILD_TYPE=Release RESULT_VARIABLE rc)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "consumer configure failed (${rc})")
endif()
execute_process(COMMAND ${CMAKE_COMMAND} --build ${WORK_DIR}/build RESULT_VARIABLE rc)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "consumer build failed (${rc})")
endif()
execute_process(COMMAND ${WORK_DIR}/build/consumer RESULT_VARIABLE rc)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "consumer returned ${rc}")
endif()
execute_process(COMMAND ${WORK_DIR}/build/refine ${SOURCE_DIR}/data/model_exact.csv
  RESULT_VARIABLE rc)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "refine returned ${rc}")
endif()
execute_process(COMMAND ${WORK_DIR}/build/refine3d RESULT_VARIABLE rc)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "refine3d returned ${rc}")
endif()
# With the Python module: the installed package imports and fits.
if(PYTHON)
  execute_process(COMMAND ${CMAKE_COMMAND} -E env
      PYTHONPATH=${WORK_DIR}/prefix/${PYTHON_DIR}
      ${PYTHON} -c "import imusysid, imusysid.fleet; assert imusysid.__file__.startswith('${WORK_DIR}/prefix'); print(imusysid.identify('${SOURCE_DIR}/data/model_exact.csv', estimators='lm')['parameters'])"
    RESULT_VARIABLE rc)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "the installed Python package failed (${rc})")
  endif()
endif()
