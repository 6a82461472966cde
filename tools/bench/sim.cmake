# Area: sim. bench_sim: wall time per simulated second of the cloth simulator (full and reduced
# gown; pull alone and whole trial), peak memory per simulation, against a baseline in the same run.
add_executable(bench_sim ${CMAKE_CURRENT_LIST_DIR}/bench_sim.cpp)
target_link_libraries(bench_sim PRIVATE dg_sim)
