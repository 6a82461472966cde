# gown: mesh loading and reduction (dressguard gown --reduced).
add_executable(bench_gown ${CMAKE_CURRENT_LIST_DIR}/bench_gown.cpp)
target_link_libraries(bench_gown PRIVATE dg_gown)
