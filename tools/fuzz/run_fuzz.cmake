# ctest fuzz_dgm_loader / fuzz_predictor_traffic: a fresh seed corpus of KIND (dg_fuzz_seeds
# dgm|predictor), then a bounded libFuzzer run; any crash, report, leak or broken rule fails.
file(REMOVE_RECURSE ${WORK})
file(MAKE_DIRECTORY ${WORK}/corpus)
execute_process(COMMAND ${SEEDS} ${KIND} ${WORK}/corpus RESULT_VARIABLE rc)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "seed generation failed (${rc})")
endif()
execute_process(COMMAND ${FUZZER} -runs=200000 -max_total_time=120 -seed=1 -max_len=8192 -print_final_stats=1
                        -artifact_prefix=${WORK}/ ${WORK}/corpus
                RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
string(REGEX MATCH "stat::number_of_executed_units: *[0-9]+" units "${err}")
message(STATUS "${KIND}: ${units}")
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "the ${KIND} fuzz target found a failure (exit ${rc}); artifacts in ${WORK}\n${err}")
endif()
