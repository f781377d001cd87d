# Runs an example with arguments it must refuse, and checks that it says why and exits with the
# expected status (not a crash). Arguments: -DPROGRAM=... -DARGUMENTS=a|b|c -DEXIT_CODE=n
# -DSTDERR_REGEX=...
string(REPLACE "|" ";" arguments "${ARGUMENTS}")
execute_process(COMMAND "${PROGRAM}" ${arguments} RESULT_VARIABLE result OUTPUT_VARIABLE output
                ERROR_VARIABLE error)
if(NOT result STREQUAL "${EXIT_CODE}")
  message(FATAL_ERROR "${PROGRAM} ${arguments}: exit status ${result}, expected ${EXIT_CODE}\n"
                      "stdout: ${output}\nstderr: ${error}")
endif()
if(NOT error MATCHES "${STDERR_REGEX}")
  message(FATAL_ERROR "${PROGRAM} ${arguments}: stderr does not match '${STDERR_REGEX}':\n${error}")
endif()
