# The checks the deployment tests share (tests/predictor/install_layout.cmake for the predictor,
# tests/robot/bridge_install_layout.cmake for the bridge): both ship a binary and a systemd unit
# template, one instance per CAN interface, installed by `cmake --install`.
#   include(${CMAKE_CURRENT_LIST_DIR}/../install_layout_checks.cmake)

# Runs `cmake --install` (the command in ARGN); WHAT says which, in the failure.
function(install_build what)
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE rc OUTPUT_QUIET)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "cmake --install ${what} failed: ${rc}")
  endif()
endfunction()

# A path that WHAT names is this install's: in its tree (not another install's, left by an
# earlier one under the configured prefix) and there. ROOT goes before the absolute paths the
# unit names (the DESTDIR, or nothing); TREE is the install's folder.
function(check_placed what named root tree)
  string(FIND "${root}${named}" "${tree}/" at)
  if(NOT at EQUAL 0 OR NOT EXISTS "${root}${named}")
    message(FATAL_ERROR "${what} names ${named}, which this install (in ${tree}) did not put there")
  endif()
endfunction()

# OUT: the one unit file NAME under TREE.
function(find_unit tree name out)
  file(GLOB_RECURSE units "${tree}/*/${name}")
  list(LENGTH units n)
  if(NOT n EQUAL 1)
    message(FATAL_ERROR "expected one ${name} under ${tree}, found ${n}")
  endif()
  set(${out} "${units}" PARENT_SCOPE)
endfunction()

# The unit's ExecStart matches REGEX (FORM says it in words, for the failure); OUT_1 and OUT_2
# get its first two groups.
function(match_exec unit regex form out_1 out_2)
  file(STRINGS "${unit}" exec REGEX "^ExecStart=")
  if(NOT exec MATCHES "${regex}")
    message(FATAL_ERROR "${unit}: ExecStart is not '${form}': ${exec}")
  endif()
  set(${out_1} "${CMAKE_MATCH_1}" PARENT_SCOPE)
  set(${out_2} "${CMAKE_MATCH_2}" PARENT_SCOPE)
endfunction()

# OUT: the first group of REGEX on the line of FILE that matches it; WHAT says what is missing.
function(file_value file regex what out)
  file(STRINGS "${file}" lines REGEX "${regex}")
  if(NOT lines MATCHES "${regex}")
    message(FATAL_ERROR "${file}: no ${what}: '${lines}'")
  endif()
  set(${out} "${CMAKE_MATCH_1}" PARENT_SCOPE)
endfunction()

# `cmake --install` creates no user: a unit that runs as a named one must have systemd make it
# (DynamicUser=yes), or it cannot start (status 217/USER) and the robot runs unguarded.
function(check_unit_user unit)
  file(STRINGS "${unit}" user REGEX "^User=")
  file(STRINGS "${unit}" dynamic REGEX "^DynamicUser=yes$")
  if(NOT user OR NOT dynamic)
    message(FATAL_ERROR "${unit}: '${user}' but no DynamicUser=yes: the install creates no such user")
  endif()
endfunction()

# Exit 2 is bad arguments or config (--help): a restart cannot mend it, so the unit restarts on
# any other failure but not on that one (restarted, it hit the start limit and hid the reason).
function(check_unit_restart unit)
  file(STRINGS "${unit}" restart REGEX "^Restart")
  if(NOT restart MATCHES "(^|;)Restart=on-failure(;|$)" OR
     NOT restart MATCHES "RestartPreventExitStatus=([^;]* )?2( |;|$)")
    message(FATAL_ERROR "${unit}: not Restart=on-failure with RestartPreventExitStatus=2: ${restart}")
  endif()
endfunction()

# Type=notify with a watchdog (WatchdogSec= above 0), and the daemon's way to the manager open:
# RestrictAddressFamilies= must allow AF_UNIX, or the daemon's READY=1 never leaves it and the
# start ends at TimeoutStartSec= (dressguard-predictor and -bridge say READY=1 when their loop
# runs and WATCHDOG=1 from it: firmware-bridge/protocol/notify_socket.h).
function(check_unit_notify unit)
  file(STRINGS "${unit}" lines REGEX "^(Type|WatchdogSec|NotifyAccess|RestrictAddressFamilies)=")
  if(NOT lines MATCHES "(^|;)Type=notify(;|$)" OR NOT lines MATCHES "(^|;)WatchdogSec=[1-9]")
    message(FATAL_ERROR "${unit}: not Type=notify with a WatchdogSec: ${lines}")
  endif()
  if(lines MATCHES "NotifyAccess=" AND NOT lines MATCHES "NotifyAccess=main")
    message(FATAL_ERROR "${unit}: NotifyAccess other than main: ${lines}")
  endif()
  if(lines MATCHES "RestrictAddressFamilies=" AND NOT lines MATCHES "RestrictAddressFamilies=[^;~]*AF_UNIX")
    message(FATAL_ERROR "${unit}: RestrictAddressFamilies= without AF_UNIX: the daemon cannot reach "
                        "$NOTIFY_SOCKET: ${lines}")
  endif()
endfunction()

# systemd's rating of the sandbox of INSTANCE (`systemd-analyze security --offline`, 0.0 for the
# tightest to 10.0 for none), at most MAX_EXPOSURE (one decimal). The unit's hardening lines are
# what a robot maker's security review reads; one lost or loosened raises the figure.
function(check_unit_exposure analyze instance max_exposure)
  string(REPLACE "." "" threshold "${max_exposure}")
  execute_process(COMMAND ${analyze} security --offline=yes --man=no --threshold=${threshold} "${instance}"
                  RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT out MATCHES "Overall exposure level for [^:]*: ([0-9.]+)")
    message(FATAL_ERROR "systemd-analyze security of ${instance} (exit ${rc}) gave no exposure level: ${out}${err}")
  endif()
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "${instance}: exposure ${CMAKE_MATCH_1}, above ${max_exposure}:\n${out}${err}")
  endif()
  message(STATUS "systemd-analyze security: exposure ${CMAKE_MATCH_1} (at most ${max_exposure})")
endfunction()

# systemd's own check of the unit, where systemd-analyze is (it needs no running systemd): an
# instance of the template, its binary BIN at the staged path ROOT BIN, in TREE/verify, for an
# interface whose name has a '-' (the instance `systemd-escape can-arm` gives). Any message is a
# failure: verify exits 0 on unknown keys and unparsable values, which systemd then ignores.
# Then its sandbox's exposure, at most MAX_EXPOSURE (check_unit_exposure).
function(verify_unit unit root bin tree max_exposure)
  find_program(SYSTEMD_ANALYZE systemd-analyze)
  if(NOT SYSTEMD_ANALYZE)
    return()
  endif()
  get_filename_component(name "${unit}" NAME)
  string(REPLACE "@.service" "@can\\x2darm.service" instance_name "${name}")
  set(verify_dir "${tree}/verify")
  set(instance "${verify_dir}/${instance_name}")
  file(MAKE_DIRECTORY "${verify_dir}")
  file(READ "${unit}" unit_text)
  string(REPLACE "${bin}" "${root}${bin}" unit_text "${unit_text}")
  file(WRITE "${verify_dir}/${name}" "${unit_text}")
  file(CREATE_LINK "${name}" "${instance}" SYMBOLIC)
  execute_process(COMMAND ${SYSTEMD_ANALYZE} verify --man=no "${instance}"
                  RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT rc EQUAL 0 OR NOT "${out}${err}" STREQUAL "")
    message(FATAL_ERROR "systemd-analyze verify of ${unit} (exit ${rc}): ${out}${err}")
  endif()
  # Its debug log shows the unit as loaded: the binary must be given the interface's own name
  # and the unit bound to that interface's device (where this systemd prints them).
  execute_process(COMMAND ${CMAKE_COMMAND} -E env SYSTEMD_LOG_LEVEL=debug ${SYSTEMD_ANALYZE} verify --man=no
                          "${instance}" OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if("${out}${err}" MATCHES "Command Line: [^\n]*--interface ([^ \n]*)")
    set(given "${CMAKE_MATCH_1}")
    if(NOT given MATCHES "^\"?can-arm\"?$")
      message(FATAL_ERROR "${unit}: instance can\\x2darm runs with --interface ${given}, not can-arm")
    endif()
    message(STATUS "instance can\\x2darm: --interface ${given}")
  endif()
  if("${out}${err}" MATCHES "BindsTo: ([^ \n]*)")
    if(NOT CMAKE_MATCH_1 STREQUAL "sys-subsystem-net-devices-can\\x2darm.device")
      message(FATAL_ERROR "${unit}: instance can\\x2darm is bound to ${CMAKE_MATCH_1}, not can-arm's device")
    endif()
  endif()
  message(STATUS "systemd-analyze verify: the unit passes")
  check_unit_exposure(${SYSTEMD_ANALYZE} "${instance}" ${max_exposure})
endfunction()
