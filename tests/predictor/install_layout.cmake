# The predictor's deployment fits together: `cmake --install` of BUILD into a staging DESTDIR
# puts the binary, the unit, the config and the model where the unit and the config say, and
# the installed config parses (the daemon checks it before it opens any CAN socket); the unit
# is not restarted on exit 2 (bad config) and passes `systemd-analyze verify` where that exists.
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
# Exit 2 is bad arguments or config (--help): a restart cannot mend it, so the unit restarts on
# any other failure but not on that one (restarted, it hit the start limit and hid the reason).
file(STRINGS "${units}" restart REGEX "^Restart")
if(NOT restart MATCHES "(^|;)Restart=on-failure(;|$)" OR NOT restart MATCHES "RestartPreventExitStatus=([^;]* )?2( |;|$)")
  message(FATAL_ERROR "${units}: not Restart=on-failure with RestartPreventExitStatus=2: ${restart}")
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
set(model_path "${CMAKE_MATCH_1}")
if(NOT EXISTS "${STAGE}${model_path}")
  message(FATAL_ERROR "${conf} names the model ${model_path}, which the install did not put there")
endif()
# The installed config parses: the daemon reads it, then fails only on the missing interface
# (exit 1), not on the file (exit 2).
execute_process(COMMAND "${STAGE}${bin}" --config "${STAGE}${conf}" --interface dg_none --no-rt
                RESULT_VARIABLE rc ERROR_VARIABLE err OUTPUT_VARIABLE out)
if(NOT rc EQUAL 1 OR NOT err MATCHES "dg_none")
  message(FATAL_ERROR "the installed config was not accepted (exit ${rc}): ${err}")
endif()
# systemd's own check of the unit, where systemd-analyze is (it needs no running systemd): an
# instance of the template with its binary at the staged path. Any message is a failure: verify
# exits 0 on unknown keys and unparsable values, which systemd then ignores.
find_program(SYSTEMD_ANALYZE systemd-analyze)
if(SYSTEMD_ANALYZE)
  set(verify_dir "${STAGE}/verify")
  file(MAKE_DIRECTORY "${verify_dir}")
  file(READ "${units}" unit_text)
  string(REPLACE "${bin}" "${STAGE}${bin}" unit_text "${unit_text}")
  file(WRITE "${verify_dir}/dressguard-predictor@.service" "${unit_text}")
  file(CREATE_LINK dressguard-predictor@.service "${verify_dir}/dressguard-predictor@can0.service" SYMBOLIC)
  execute_process(COMMAND ${SYSTEMD_ANALYZE} verify --man=no "${verify_dir}/dressguard-predictor@can0.service"
                  RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT rc EQUAL 0 OR NOT "${out}${err}" STREQUAL "")
    message(FATAL_ERROR "systemd-analyze verify of ${units} (exit ${rc}): ${out}${err}")
  endif()
  message(STATUS "systemd-analyze verify: the unit passes")
endif()
message(STATUS "installed: ${bin}, ${conf}, ${model_path}, ${units}")
