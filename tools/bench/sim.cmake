# Area: sim. bench_sim: wall time per simulated second of the cloth simulator (full and reduced
# gown; pull alone and whole trial), peak memory per simulation, against a baseline in the same run.
add_executable(bench_sim ${CMAKE_CURRENT_LIST_DIR}/bench_sim.cpp)
target_link_libraries(bench_sim PRIVATE dg_sim)
# bench_sim_elements: one strain element per triangle against the edges + shear, and how stiff
# bending is per substep (offline/sim/MEASUREMENTS.md, session 57).
add_executable(bench_sim_elements ${CMAKE_CURRENT_LIST_DIR}/bench_sim_elements.cpp)
target_link_libraries(bench_sim_elements PRIVATE dg_sim)
target_compile_options(bench_sim_elements PRIVATE $<$<CXX_COMPILER_ID:GNU,Clang>:-ffp-contract=off>)
# bench_sim_kernels: whether the constraint stream's size or moving vertices into lanes sets the
# AVX2 kernels' pace, and the floor that leaves against the speed goals (MEASUREMENTS.md, session 76).
add_executable(bench_sim_kernels ${CMAKE_CURRENT_LIST_DIR}/bench_sim_kernels.cpp)
target_link_libraries(bench_sim_kernels PRIVATE dg_sim)
# bench_sim_vertex_pass: a vertex-centric pass (Vertex Block Descent) against the tree's
# constraint pass, its cost and its work per pass (MEASUREMENTS.md, session 77).
add_executable(bench_sim_vertex_pass ${CMAKE_CURRENT_LIST_DIR}/bench_sim_vertex_pass.cpp)
target_link_libraries(bench_sim_vertex_pass PRIVATE dg_sim)
