# calib area (offline/calib): CMA-ES against pagmo2's, and the calibration pipeline benchmark.
find_package(Pagmo QUIET)
if(Pagmo_FOUND)
  add_executable(bench_calib_cmaes ${CMAKE_CURRENT_LIST_DIR}/bench_calib_cmaes.cpp)
  target_link_libraries(bench_calib_cmaes PRIVATE dg_calib Pagmo::pagmo)
else()
  message(STATUS "pagmo2 not found (libpagmo-dev): bench_calib_cmaes is not built")
endif()
