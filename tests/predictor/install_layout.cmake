# The predictor's deployment fits together: `cmake --install` of BUILD, into a staging DESTDIR
# and with another prefix (`--prefix P`), puts the binary, the unit, the config and the model
# where the unit and the config say, and the installed config parses (the daemon checks it
# before it opens any CAN socket); the unit is not restarted on exit 2 (bad config) and passes
# `systemd-analyze verify` where that exists.
#   cmake -DBUILD=... -DSTAGE=... -P install_layout.cmake

# A path that WHAT names is this install's: in its tree (not another install's, left by an
# earlier one under the configured prefix) and there. ROOT and TREE: check_install's.
function(check_placed what named)
  string(FIND "${root}${named}" "${tree}/" at)
  if(NOT at EQUAL 0 OR NOT EXISTS "${root}${named}")
    message(FATAL_ERROR "${what} names ${named}, which this install (in ${tree}) did not put there")
  endif()
endfunction()

# Checks the install in folder TREE; ROOT goes before the absolute paths the unit and the config
# name (the DESTDIR, or nothing).
function(check_install root tree)
  file(GLOB_RECURSE units "${tree}/*/dressguard-predictor@.service")
  list(LENGTH units n)
  if(NOT n EQUAL 1)
    message(FATAL_ERROR "expected one dressguard-predictor@.service under ${tree}, found ${n}")
  endif()
  file(STRINGS "${units}" exec REGEX "^ExecStart=")
  # %I: the instance unescaped is the interface's name (%i, escaped, names the device unit).
  if(NOT exec MATCHES "^ExecStart=([^ ]+) --config ([^ ]+) --interface %I$")
    message(FATAL_ERROR "${units}: ExecStart is not 'BINARY --config FILE --interface %I': ${exec}")
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
  if(NOT restart MATCHES "(^|;)Restart=on-failure(;|$)" OR
     NOT restart MATCHES "RestartPreventExitStatus=([^;]* )?2( |;|$)")
    message(FATAL_ERROR "${units}: not Restart=on-failure with RestartPreventExitStatus=2: ${restart}")
  endif()
  check_placed("${units}" "${bin}")
  check_placed("${units}" "${conf}")
  file(STRINGS "${root}${conf}" model REGEX "^model *=")
  if(NOT model MATCHES "^model *= *([^ #]+)")
    message(FATAL_ERROR "${conf}: no model line")
  endif()
  set(model_path "${CMAKE_MATCH_1}")
  check_placed("${conf}" "${model_path}")
  # The installed config parses: the daemon reads it, then fails only on the missing interface
  # (exit 1), not on the file (exit 2).
  execute_process(COMMAND "${root}${bin}" --config "${root}${conf}" --interface dg_none --no-rt
                  RESULT_VARIABLE rc ERROR_VARIABLE err OUTPUT_VARIABLE out)
  if(NOT rc EQUAL 1 OR NOT err MATCHES "dg_none")
    message(FATAL_ERROR "the installed config was not accepted (exit ${rc}): ${err}")
  endif()
  # systemd's own check of the unit, where systemd-analyze is (it needs no running systemd): an
  # instance of the template with its binary at the staged path, for an interface whose name has
  # a '-' (the instance `systemd-escape can-arm` gives). Any message is a failure: verify exits 0
  # on unknown keys and unparsable values, which systemd then ignores.
  find_program(SYSTEMD_ANALYZE systemd-analyze)
  if(SYSTEMD_ANALYZE)
    set(verify_dir "${tree}/verify")
    set(instance "${verify_dir}/dressguard-predictor@can\\x2darm.service")
    file(MAKE_DIRECTORY "${verify_dir}")
    file(READ "${units}" unit_text)
    string(REPLACE "${bin}" "${root}${bin}" unit_text "${unit_text}")
    file(WRITE "${verify_dir}/dressguard-predictor@.service" "${unit_text}")
    file(CREATE_LINK dressguard-predictor@.service "${instance}" SYMBOLIC)
    execute_process(COMMAND ${SYSTEMD_ANALYZE} verify --man=no "${instance}"
                    RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
    if(NOT rc EQUAL 0 OR NOT "${out}${err}" STREQUAL "")
      message(FATAL_ERROR "systemd-analyze verify of ${units} (exit ${rc}): ${out}${err}")
    endif()
    # Its debug log shows the unit as loaded: the daemon must be given the interface's own name
    # and the unit bound to that interface's device (where this systemd prints them).
    execute_process(COMMAND ${CMAKE_COMMAND} -E env SYSTEMD_LOG_LEVEL=debug ${SYSTEMD_ANALYZE} verify --man=no
                            "${instance}" OUTPUT_VARIABLE out ERROR_VARIABLE err)
    if("${out}${err}" MATCHES "Command Line: [^\n]*--interface ([^\n]*)")
      set(given "${CMAKE_MATCH_1}")
      if(NOT given MATCHES "^\"?can-arm\"?$")
        message(FATAL_ERROR "${units}: instance can\\x2darm runs the daemon with --interface ${given}, not can-arm")
      endif()
      message(STATUS "instance can\\x2darm: --interface ${given}")
    endif()
    if("${out}${err}" MATCHES "BindsTo: ([^ \n]*)")
      if(NOT CMAKE_MATCH_1 STREQUAL "sys-subsystem-net-devices-can\\x2darm.device")
        message(FATAL_ERROR "${units}: instance can\\x2darm is bound to ${CMAKE_MATCH_1}, not can-arm's device")
      endif()
    endif()
    message(STATUS "systemd-analyze verify: the unit passes")
  endif()
  message(STATUS "installed: ${bin}, ${conf}, ${model_path}, ${units}")
endfunction()

function(install_build what)
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE rc OUTPUT_QUIET)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "cmake --install ${what} failed: ${rc}")
  endif()
endfunction()

file(REMOVE_RECURSE "${STAGE}")
# The configured prefix, staged under a DESTDIR as a package build does.
install_build("into DESTDIR ${STAGE}/destdir"
              ${CMAKE_COMMAND} -E env DESTDIR=${STAGE}/destdir ${CMAKE_COMMAND} --install ${BUILD})
check_install("${STAGE}/destdir" "${STAGE}/destdir")
# Another prefix at install time: the unit and the config must name its paths, not the
# configured prefix's (they did: a binary that is not there, or an older one).
install_build("--prefix ${STAGE}/prefix" ${CMAKE_COMMAND} --install ${BUILD} --prefix ${STAGE}/prefix)
check_install("" "${STAGE}/prefix")
