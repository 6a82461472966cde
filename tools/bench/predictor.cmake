# Area: predictor (robot side). bench_predictor: per-sample processing of the daemon core against
# the bare filter step (same run), with the stop frame sent, and end to end through a CAN port
# (in-process bus here; SocketCAN vcan in the test VM with --e2e IFACE).
if(TARGET dg_predictor_daemon)
  add_executable(bench_predictor ${CMAKE_CURRENT_LIST_DIR}/bench_predictor.cpp)
  target_link_libraries(bench_predictor PRIVATE dg_predictor_daemon)
endif()
