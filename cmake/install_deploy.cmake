# Run by `cmake --install` (dg_install_deploy, cmake/deploy.cmake): writes a systemd unit and the
# config file it reads with the paths of this install, and installs them. At install time, not at
# configure time: `cmake --install --prefix P` puts the binary (and the predictor's model) under
# P, and a unit or config written at configure time named the configured prefix instead (a
# binary that is not there, or an older one). Set by the caller: DG_UNIT_IN, DG_CONF_IN,
# DG_CONF_NAME (the installed config's name), DG_OUT, DG_BINDIR, DG_SYSCONFDIR, DG_DATADIR
# (GNUInstallDirs' dirs, as configured).

# An install dir as this install places it: a relative one is under the install-time prefix.
function(dg_install_dir dir out)
  if(IS_ABSOLUTE "${dir}")
    set(${out} "${dir}" PARENT_SCOPE)
  else()
    set(${out} "${CMAKE_INSTALL_PREFIX}/${dir}" PARENT_SCOPE)
  endif()
endfunction()

# The config's folder, with GNUInstallDirs' rule for it: under the prefix /usr (or /) it is
# /etc, under /opt/PKG it is /etc/opt/PKG (the FHS's places), else PREFIX/etc.
function(dg_sysconf_dir dir out)
  if(IS_ABSOLUTE "${dir}" OR NOT dir STREQUAL "etc")
    dg_install_dir("${dir}" full)
  elseif(CMAKE_INSTALL_PREFIX MATCHES "^/(usr/?)?$")
    set(full "/etc")
  elseif(CMAKE_INSTALL_PREFIX MATCHES "^/opt/(.+)$")
    set(full "/etc/opt/${CMAKE_MATCH_1}")
  else()
    set(full "${CMAKE_INSTALL_PREFIX}/etc")
  endif()
  set(${out} "${full}" PARENT_SCOPE)
endfunction()

# The names the unit's template uses; the unit is named as its template without ".in".
dg_install_dir("${DG_BINDIR}" CMAKE_INSTALL_FULL_BINDIR)
dg_sysconf_dir("${DG_SYSCONFDIR}" CMAKE_INSTALL_FULL_SYSCONFDIR)
dg_install_dir("${DG_DATADIR}" CMAKE_INSTALL_FULL_DATADIR)
get_filename_component(dg_unit "${DG_UNIT_IN}" NAME)
string(REGEX REPLACE "\\.in$" "" dg_unit "${dg_unit}")
configure_file("${DG_UNIT_IN}" "${DG_OUT}/${dg_unit}" @ONLY)
# A path to the shipped data in the config (the predictor's model) is this install's.
file(READ "${DG_CONF_IN}" conf)
string(REPLACE "/usr/local/share/dressguard/" "${CMAKE_INSTALL_FULL_DATADIR}/dressguard/" conf "${conf}")
file(WRITE "${DG_OUT}/${DG_CONF_NAME}" "${conf}")
file(INSTALL DESTINATION "${CMAKE_INSTALL_PREFIX}/lib/systemd/system" TYPE FILE FILES "${DG_OUT}/${dg_unit}")
file(INSTALL DESTINATION "${CMAKE_INSTALL_FULL_SYSCONFDIR}/dressguard" TYPE FILE FILES "${DG_OUT}/${DG_CONF_NAME}")
