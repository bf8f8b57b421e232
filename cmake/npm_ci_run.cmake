# Runs `npm ci` in DIR (cmake -DNPM=... -DDIR=... -DSTAMP=... -P npm_ci_run.cmake) and touches
# STAMP; stops the build with a message that says what failed and why when it cannot.
execute_process(COMMAND ${NPM} ci --no-audit --no-fund --ignore-scripts --loglevel=error
  WORKING_DIRECTORY ${DIR} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "npm ci failed in ${DIR} (exit ${rc}): the packages of its package-lock.json "
    "come from the npm registry at build time, which must be reachable (npm's own proxy and "
    "registry settings apply).\n${err}")
endif()
file(TOUCH ${STAMP})
