# The bridge's deployment fits together: `cmake --install` of BUILD's `bridge` component (all a
# bridge's host needs) into a staging DESTDIR puts the binary and the options file where the
# unit says, the unit runs as a user systemd makes with the rights the bridge's real-time setup
# and serial line need, and the installed options are accepted (the bridge checks them before it
# opens any CAN socket).
#   cmake -DBUILD=... -DSTAGE=... -P bridge_install_layout.cmake
file(REMOVE_RECURSE "${STAGE}")
execute_process(COMMAND ${CMAKE_COMMAND} -E env DESTDIR=${STAGE} ${CMAKE_COMMAND} --install ${BUILD} --component bridge
                RESULT_VARIABLE rc OUTPUT_QUIET)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "cmake --install into ${STAGE} failed: ${rc}")
endif()
file(GLOB_RECURSE units "${STAGE}/*/dressguard-bridge@.service")
list(LENGTH units n)
if(NOT n EQUAL 1)
  message(FATAL_ERROR "expected one dressguard-bridge@.service under ${STAGE}, found ${n}")
endif()

# want(REGEX WHY): the unit has a line matching REGEX, else it fails saying WHY.
function(want regex why)
  file(STRINGS "${units}" line REGEX "${regex}")
  if(NOT line)
    message(FATAL_ERROR "${units}: no line '${regex}': ${why}")
  endif()
endfunction()
want("^BindsTo=sys-subsystem-net-devices-%i.device$" "the unit must stop when its CAN interface goes")
want("^User=" "a named service user")
# `cmake --install` creates no user: a unit that runs as a named one must have systemd make it,
# or it cannot start (status 217/USER) and no stop reaches the robot.
want("^DynamicUser=yes$" "the install creates no user")
want("^SupplementaryGroups=.*dialout" "the serial devices belong to group dialout")
want("^AmbientCapabilities=.*CAP_SYS_NICE" "SCHED_FIFO needs it (a user without it runs SCHED_OTHER)")
want("^AmbientCapabilities=.*CAP_IPC_LOCK" "mlockall needs it")
file(STRINGS "${units}" hidden REGEX "^PrivateDevices=(yes|true|1)$")
if(hidden)
  message(FATAL_ERROR "${units}: ${hidden} hides the serial devices from the bridge")
endif()

file(STRINGS "${units}" exec REGEX "^ExecStart=")
if(NOT exec MATCHES "^ExecStart=([^ ]+) --interface %i \\$DRESSGUARD_BRIDGE_OPTIONS$")
  message(FATAL_ERROR "${units}: ExecStart is not 'BINARY --interface %i $DRESSGUARD_BRIDGE_OPTIONS': ${exec}")
endif()
set(bin "${CMAKE_MATCH_1}")
file(STRINGS "${units}" envfile REGEX "^EnvironmentFile=")
if(NOT envfile MATCHES "^EnvironmentFile=(/[^ ]+)$")
  message(FATAL_ERROR "${units}: no required EnvironmentFile: ${envfile}")
endif()
set(env "${CMAKE_MATCH_1}")
foreach(f "${bin}" "${env}")
  if(NOT EXISTS "${STAGE}${f}")
    message(FATAL_ERROR "${units} names ${f}, which the install did not put there")
  endif()
endforeach()
file(STRINGS "${STAGE}${env}" options REGEX "^DRESSGUARD_BRIDGE_OPTIONS=")
if(NOT options MATCHES "^DRESSGUARD_BRIDGE_OPTIONS=\"([^\"]*)\"$")
  message(FATAL_ERROR "${env}: no line DRESSGUARD_BRIDGE_OPTIONS=\"...\"")
endif()
# The installed options are accepted: the bridge fails only on the missing interface (exit 1),
# not on an option (exit 2). --no-rt: the test changes no scheduling.
separate_arguments(args UNIX_COMMAND "${CMAKE_MATCH_1}")
execute_process(COMMAND "${STAGE}${bin}" --interface dg_none ${args} --no-rt
                RESULT_VARIABLE rc ERROR_VARIABLE err OUTPUT_VARIABLE out)
if(NOT rc EQUAL 1 OR NOT err MATCHES "dg_none")
  message(FATAL_ERROR "the installed options were not accepted (exit ${rc}): ${err}")
endif()
message(STATUS "installed: ${bin}, ${env}, ${units}")
