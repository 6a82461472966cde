# The predictor's deployment fits together: `cmake --install` of BUILD, into a staging DESTDIR
# and with another prefix (`--prefix P`), puts the binary, the unit, the config and the model
# where the unit and the config say, and the installed config parses (the daemon checks it
# before it opens any CAN socket); the unit is not restarted on exit 2 (bad config), passes
# `systemd-analyze verify` and keeps its sandbox (`systemd-analyze security`) where that exists.
#   cmake -DBUILD=... -DSTAGE=... -P install_layout.cmake

include(${CMAKE_CURRENT_LIST_DIR}/../install_layout_checks.cmake)

# Checks the install in folder TREE; ROOT goes before the absolute paths the unit and the config
# name (the DESTDIR, or nothing).
function(check_install root tree)
  find_unit("${tree}" dressguard-predictor@.service units)
  # %I: the instance unescaped is the interface's name (%i, escaped, names the device unit).
  match_exec("${units}" "^ExecStart=([^ ]+) --config ([^ ]+) --interface %I$"
             "BINARY --config FILE --interface %I" bin conf)
  check_unit_user("${units}")
  check_unit_restart("${units}")
  check_unit_notify("${units}")
  check_placed("${units}" "${bin}" "${root}" "${tree}")
  check_placed("${units}" "${conf}" "${root}" "${tree}")
  file_value("${root}${conf}" "^model *= *([^ #]+)" "model line" model_path)
  check_placed("${conf}" "${model_path}" "${root}" "${tree}")
  # The installed config parses: the daemon reads it, then fails only on the missing interface
  # (exit 1), not on the file (exit 2).
  execute_process(COMMAND "${root}${bin}" --config "${root}${conf}" --interface dg_none --no-rt
                  RESULT_VARIABLE rc ERROR_VARIABLE err OUTPUT_VARIABLE out)
  if(NOT rc EQUAL 1 OR NOT err MATCHES "dg_none")
    message(FATAL_ERROR "the installed config was not accepted (exit ${rc}): ${err}")
  endif()
  # Exposure 1.6 (systemd 252; 8.4 before its sandbox): what is left is the daemon's need, its
  # three capabilities, SocketCAN (an "exotic" family), SCHED_FIFO, the host's network and users.
  verify_unit("${units}" "${root}" "${bin}" "${tree}" 1.6)
  message(STATUS "installed: ${bin}, ${conf}, ${model_path}, ${units}")
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
