# The predictor's deployment fits together: `cmake --install` of BUILD into a staging DESTDIR
# puts the binary, the unit, the config and the model where the unit and the config say, and
# the installed config parses (the daemon checks it before it opens any CAN socket).
#   cmake -DBUILD=... -DSTAGE=... -P install_layout.cmake
file(REMOVE_RECURSE "${STAGE}")
execute_process(COMMAND ${CMAKE_COMMAND} -E env DESTDIR=${STAGE} ${CMAKE_COMMAND} --install ${BUILD}
                RESULT_VARIABLE rc OUTPUT_QUIET)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "cmake --install into ${STAGE} failed: ${rc}")
endif()
file(GLOB_RECURSE units "${STAGE}/*/dressguard-predictor@.service")
list(LENGTH units n)
if(NOT n EQUAL 1)
  message(FATAL_ERROR "expected one dressguard-predictor@.service under ${STAGE}, found ${n}")
endif()
file(STRINGS "${units}" exec REGEX "^ExecStart=")
if(NOT exec MATCHES "^ExecStart=([^ ]+) --config ([^ ]+) --interface %i$")
  message(FATAL_ERROR "${units}: ExecStart is not 'BINARY --config FILE --interface %i': ${exec}")
endif()
set(bin "${CMAKE_MATCH_1}")
set(conf "${CMAKE_MATCH_2}")
# `cmake --install` creates no user: a unit that runs as a named one must have systemd make it
# (DynamicUser=yes), or it cannot start (status 217/USER) and the robot runs without a predictor.
file(STRINGS "${units}" user REGEX "^User=")
file(STRINGS "${units}" dynamic REGEX "^DynamicUser=yes$")
if(user AND NOT dynamic)
  message(FATAL_ERROR "${units}: ${user} but no DynamicUser=yes: the install creates no such user")
endif()
foreach(f "${bin}" "${conf}")
  if(NOT EXISTS "${STAGE}${f}")
    message(FATAL_ERROR "${units} names ${f}, which the install did not put there")
  endif()
endforeach()
file(STRINGS "${STAGE}${conf}" model REGEX "^model *=")
if(NOT model MATCHES "^model *= *([^ #]+)")
  message(FATAL_ERROR "${conf}: no model line")
endif()
if(NOT EXISTS "${STAGE}${CMAKE_MATCH_1}")
  message(FATAL_ERROR "${conf} names the model ${CMAKE_MATCH_1}, which the install did not put there")
endif()
# The installed config parses: the daemon reads it, then fails only on the missing interface
# (exit 1), not on the file (exit 2).
execute_process(COMMAND "${STAGE}${bin}" --config "${STAGE}${conf}" --interface dg_none --no-rt
                RESULT_VARIABLE rc ERROR_VARIABLE err OUTPUT_VARIABLE out)
if(NOT rc EQUAL 1 OR NOT err MATCHES "dg_none")
  message(FATAL_ERROR "the installed config was not accepted (exit ${rc}): ${err}")
endif()
message(STATUS "installed: ${bin}, ${conf}, ${CMAKE_MATCH_1}, ${units}")
