# The bridge's deployment fits together: `cmake --install` of BUILD's `bridge` component (all a
# bridge's host needs) into a staging DESTDIR, and with another prefix (`--prefix P`), puts the
# binary and the options file where the unit says, the unit runs as a user systemd makes with
# the rights the bridge's real-time setup and serial line need, and the installed options are
# accepted (the bridge checks them before it opens any CAN socket); the unit is not restarted on
# exit 2 (bad arguments), passes the instance's interface unescaped, and passes
# `systemd-analyze verify` and keeps its sandbox (`systemd-analyze security`) where that exists.
#   cmake -DBUILD=... -DSTAGE=... -P bridge_install_layout.cmake
include(${CMAKE_CURRENT_LIST_DIR}/../install_layout_checks.cmake)

# want(UNIT REGEX WHY): the unit has a line matching REGEX, else it fails saying WHY.
function(want unit regex why)
  file(STRINGS "${unit}" line REGEX "${regex}")
  if(NOT line)
    message(FATAL_ERROR "${unit}: no line '${regex}': ${why}")
  endif()
endfunction()

# The unit's rights: what the bridge's real-time setup and serial line need, nothing hiding them.
function(check_rights unit)
  want("${unit}" "^BindsTo=sys-subsystem-net-devices-%i.device$" "the unit must stop when its CAN interface goes")
  check_unit_user("${unit}")
  want("${unit}" "^SupplementaryGroups=.*dialout" "the serial devices belong to group dialout")
  want("${unit}" "^AmbientCapabilities=.*CAP_SYS_NICE" "SCHED_FIFO needs it (a user without it runs SCHED_OTHER)")
  want("${unit}" "^AmbientCapabilities=.*CAP_IPC_LOCK" "mlockall needs it")
  # DevicePolicy=closed: the serial lines must be allowed by name, the default sensor's first.
  want("${unit}" "^DeviceAllow=char-ttyUSB rw$" "the default sensor, rtu-stream:/dev/ttyUSB0, is a USB adapter")
  file(STRINGS "${unit}" hidden REGEX "^PrivateDevices=(yes|true|1)$")
  if(hidden)
    message(FATAL_ERROR "${unit}: ${hidden} hides the serial devices from the bridge")
  endif()
endfunction()

# Checks the install in folder TREE; ROOT goes before the absolute paths the unit names (the
# DESTDIR, or nothing).
function(check_install root tree)
  find_unit("${tree}" dressguard-bridge@.service unit)
  check_rights("${unit}")
  # %I: the instance unescaped is the interface's name (%i, escaped, names the device unit).
  match_exec("${unit}" "^ExecStart=([^ ]+) --interface %I \\$DRESSGUARD_BRIDGE_OPTIONS$"
             "BINARY --interface %I $DRESSGUARD_BRIDGE_OPTIONS" bin unused)
  check_unit_restart("${unit}")
  check_unit_notify("${unit}")
  file_value("${unit}" "^EnvironmentFile=(/[^ ]+)$" "required EnvironmentFile" env)
  check_placed("${unit}" "${bin}" "${root}" "${tree}")
  check_placed("${unit}" "${env}" "${root}" "${tree}")
  file_value("${root}${env}" "^DRESSGUARD_BRIDGE_OPTIONS=\"([^\"]*)\"$" "line DRESSGUARD_BRIDGE_OPTIONS=\"...\""
             options)
  # The installed options are accepted: the bridge fails only on the missing interface (exit 1),
  # not on an option (exit 2). --no-rt: the test changes no scheduling.
  separate_arguments(args UNIX_COMMAND "${options}")
  execute_process(COMMAND "${root}${bin}" --interface dg_none ${args} --no-rt
                  RESULT_VARIABLE rc ERROR_VARIABLE err OUTPUT_VARIABLE out)
  if(NOT rc EQUAL 1 OR NOT err MATCHES "dg_none")
    message(FATAL_ERROR "the installed options were not accepted (exit ${rc}): ${err}")
  endif()
  # Exposure 2.1 (systemd 252; 8.4 before its sandbox): what is left is the bridge's need, its
  # two capabilities, group dialout and the serial lines, SocketCAN and Modbus TCP (IPv4), and
  # SCHED_FIFO, the host's network and users.
  verify_unit("${unit}" "${root}" "${bin}" "${tree}" 2.1)
  message(STATUS "installed: ${bin}, ${env}, ${unit}")
endfunction()

file(REMOVE_RECURSE "${STAGE}")
install_build("into DESTDIR ${STAGE}/destdir" ${CMAKE_COMMAND} -E env DESTDIR=${STAGE}/destdir
              ${CMAKE_COMMAND} --install ${BUILD} --component bridge)
check_install("${STAGE}/destdir" "${STAGE}/destdir")
# Another prefix at install time: the unit must name its paths, not the configured prefix's (it
# did: a binary that is not there, or an older one, and an options file that is not there).
install_build("--prefix ${STAGE}/prefix" ${CMAKE_COMMAND} --install ${BUILD} --component bridge
              --prefix ${STAGE}/prefix)
check_install("" "${STAGE}/prefix")
