# dg_install_deploy(UNIT_IN CONF_IN CONF_NAME COMPONENT): installs a systemd unit template and the
# config file it reads as CONF_NAME in SYSCONFDIR/dressguard, both written by `cmake --install`
# with that install's paths (cmake/install_deploy.cmake), in install component COMPONENT. Shared
# by the predictor daemon and the firmware bridge.
include(GNUInstallDirs)
function(dg_install_deploy unit_in conf_in conf_name component)
  install(CODE "set(DG_UNIT_IN \"${unit_in}\")
    set(DG_CONF_IN \"${conf_in}\")
    set(DG_CONF_NAME \"${conf_name}\")
    set(DG_OUT \"${CMAKE_CURRENT_BINARY_DIR}/install\")
    set(DG_BINDIR \"${CMAKE_INSTALL_BINDIR}\")
    set(DG_SYSCONFDIR \"${CMAKE_INSTALL_SYSCONFDIR}\")
    set(DG_DATADIR \"${CMAKE_INSTALL_DATADIR}\")
    include(\"${CMAKE_SOURCE_DIR}/cmake/install_deploy.cmake\")" COMPONENT ${component})
endfunction()
