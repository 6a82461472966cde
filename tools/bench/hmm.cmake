# hmm area: bench_hmm, the online forward filter (3 classes x 10 states, per-sample latency against a
# plain full-matrix forward step), training time, and per-iteration time against GHMM (the GHMM part
# only when libghmm-dev is installed).
add_executable(bench_hmm ${CMAKE_CURRENT_LIST_DIR}/bench_hmm.cpp)
target_link_libraries(bench_hmm PRIVATE dg_hmm dg_filter)
if(DRESSGUARD_WITH_GHMM)
  find_path(GHMM_INCLUDE_DIR ghmm/smodel.h)
  find_library(GHMM_LIBRARY ghmm)
  if(GHMM_INCLUDE_DIR AND GHMM_LIBRARY)
    target_sources(bench_hmm PRIVATE ${CMAKE_SOURCE_DIR}/tools/ghmm/ghmm_bridge.cpp)
    target_include_directories(bench_hmm PRIVATE ${CMAKE_SOURCE_DIR}/tools/ghmm ${GHMM_INCLUDE_DIR})
    target_link_libraries(bench_hmm PRIVATE ${GHMM_LIBRARY})
    target_compile_definitions(bench_hmm PRIVATE DG_WITH_GHMM=1)
  endif()
endif()
