# Installs the built priormap into a temporary prefix, then configures, builds and runs
# examples/consumer against it. Arguments: -DBINARY_DIR=... -DSOURCE_DIR=... -DWORK_DIR=...
file(REMOVE_RECURSE "${WORK_DIR}")
file(MAKE_DIRECTORY "${WORK_DIR}")

function(run)
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE result OUTPUT_VARIABLE output ERROR_VARIABLE output)
  if(NOT result EQUAL 0)
    message(FATAL_ERROR "failed (${result}): ${ARGN}\n${output}")
  endif()
endfunction()

run(${CMAKE_COMMAND} --install "${BINARY_DIR}" --prefix "${WORK_DIR}/prefix")
run(${CMAKE_COMMAND} -S "${SOURCE_DIR}/examples/consumer" -B "${WORK_DIR}/build" -G Ninja
    -DCMAKE_BUILD_TYPE=Release "-DCMAKE_PREFIX_PATH=${WORK_DIR}/prefix")
run(${CMAKE_COMMAND} --build "${WORK_DIR}/build")
run("${WORK_DIR}/build/consumer" "${WORK_DIR}")
foreach(file consumer-scan.json consumer-scan.png)
  if(NOT EXISTS "${WORK_DIR}/${file}")
    message(FATAL_ERROR "the consumer did not write ${file}")
  endif()
endforeach()
# The installed Python package (when the module was built) imports from where it was put, which
# is where the system python3 looks: lib/python3.X/dist-packages, or lib/python3/dist-packages
# for the prefix /usr.
file(GLOB python_packages "${WORK_DIR}/prefix/lib/python*/dist-packages/priormap")
if(python_packages AND EXISTS /usr/bin/python3)
  execute_process(COMMAND /usr/bin/python3 -c
                          "import sys; print(f'python{sys.version_info[0]}.{sys.version_info[1]}')"
                  OUTPUT_VARIABLE python_version OUTPUT_STRIP_TRAILING_WHITESPACE)
  if(NOT python_packages MATCHES "/lib/(${python_version}|python3)/dist-packages/priormap")
    message(FATAL_ERROR "the Python package went to ${python_packages}, where ${python_version} "
                        "does not look")
  endif()
  get_filename_component(site "${python_packages}" DIRECTORY)
  run(${CMAKE_COMMAND} -E env "PYTHONPATH=${site}" /usr/bin/python3 -c
      "import priormap; assert priormap.list_priors()")
endif()
file(REMOVE_RECURSE "${WORK_DIR}")
