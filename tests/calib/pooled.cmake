# tools/bench/bench_calib_pipeline pooled with several seeds: each seed's STC of a file, trained
# on that seed's part of the union, must be the STC a one-seed run trains on the same set (the
# union renumbers seed s's trials from s x per_height), and the seeds' pairing rows must be there
# for the paper's three classes and for good or missed; a seed without its folder exits 2.
# Each STC's pairing with the 1-NN must match the one-member vote's.
# -DBENCH=<bench_calib_pipeline> -DWORK=<dir> -DSTUDY=<study dir or empty> -DCAL=<a calibration>
file(REMOVE_RECURSE ${WORK})
file(MAKE_DIRECTORY ${WORK})
if(NOT STUDY)
  message("SKIP: shared/data/kapusta2016-calibration-trials not present; the pooled STCs need the study")
  return()
endif()
execute_process(COMMAND ${BENCH} pooled --calibrations ${CAL} --seed 1,2 --synth ${WORK}/s1
                RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT rc EQUAL 2 OR NOT err MATCHES "pooled: --synth needs one folder per --seed \\(2 seeds, 1 folders\\)")
  message(FATAL_ERROR "pooled with two seeds and one folder (${rc}):\n${out}\n${err}")
endif()
# Three synthesized trials per height and seed (18 simulations of the reduced gown, about a minute
# on two threads), then the union of the two sets from the folders.
set(common pooled --calibrations ${CAL} --per-height 3 --threads 2)
foreach(run s1 s2 union)
  if(run STREQUAL "union")
    set(args --seed 1,2 --synth ${WORK}/s1,${WORK}/s2)
  else()
    string(SUBSTRING ${run} 1 1 seed)
    set(args --seed ${seed} --synth ${WORK}/${run})
  endif()
  execute_process(COMMAND ${BENCH} ${common} ${args} RESULT_VARIABLE rc OUTPUT_VARIABLE out_${run}
                  ERROR_VARIABLE err)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "pooled ${args} (${rc}):\n${out_${run}}\n${err}")
  endif()
endforeach()
get_filename_component(stem ${CAL} NAME_WE)
# One row per force set (F_motion; + F_lateral; + F_vertical), in order: its five percentages.
function(rows text label out_var)
  string(REGEX MATCHALL "\n  ${label}: ${stem} +[0-9% ]+\\([0-9]+ trials\\)" found "${text}")
  list(LENGTH found n)
  if(NOT n EQUAL 3)
    message(FATAL_ERROR "'${label}: ${stem}' found ${n} times, not 3:\n${text}")
  endif()
  set(values "")
  foreach(row IN LISTS found)
    string(REGEX REPLACE "^\n  ${label}: ${stem} +" "" row "${row}")
    list(APPEND values "${row}")
  endforeach()
  set(${out_var} "${values}" PARENT_SCOPE)
endfunction()
rows("${out_s1}" "alone" one)
rows("${out_union}" "seed 1 alone" union_one)
rows("${out_s2}" "alone" two)
rows("${out_union}" "seed 2 alone" union_two)
if(NOT one STREQUAL union_one OR NOT two STREQUAL union_two)
  message(FATAL_ERROR "a seed's STC in the union is not its one-seed run's:\nseed 1 alone ${one}\nin the union "
                      "${union_one}\nseed 2 alone ${two}\nin the union ${union_two}")
endif()
# The good-or-missed rows (equal priors) have no one-seed counterpart (its good|missed rows use
# the training shares): present, three of each, is what is checked.
rows("${out_union}" "good\\|missed, seed 1 alone" unused)
rows("${out_union}" "good\\|missed, seed 2 alone" unused)
# CMake's regular expressions have no {n}: the five b/c p cells spelled out.
set(cell "[0-9]+/[0-9]+ [01]\\.[0-9][0-9]")
foreach(label "seed 1 vs 2" "good\\|missed, seed 1 vs 2")
  string(REGEX MATCHALL "\n  ${label}: ${stem} +${cell} ${cell} ${cell} ${cell} ${cell}\n" found "${out_union}")
  list(LENGTH found n)
  if(NOT n EQUAL 3)
    message(FATAL_ERROR "'${label}: ${stem}' (b/c p at the five cuts) found ${n} times, not 3:\n${out_union}")
  endif()
endforeach()
# Each STC against the 1-NN on its own test trials (everyone but its person), at the cuts only.
# With one calibration the vote of "the other people's STCs" is that one STC on the same trials,
# so its long-standing pairing with the 1-NN must give the same splits, force set by force set.
set(pair "([0-9]+/[0-9]+)")
foreach(run s1 s2)
  string(REGEX MATCHALL "\n  STC vs 1-NN, b/c p: ${stem} +- +${cell} ${cell} ${cell} ${cell}\n" stc_rows
         "${out_${run}}")
  string(REGEX MATCHALL "\n  vote vs 1-NN, paired: only vote / only 1-NN +- +${pair} +${pair} +${pair} +${pair}\n"
         vote_rows "${out_${run}}")
  list(LENGTH stc_rows n_stc)
  list(LENGTH vote_rows n_vote)
  if(NOT n_stc EQUAL 3 OR NOT n_vote EQUAL 3)
    message(FATAL_ERROR "${run}: 'STC vs 1-NN' rows ${n_stc}, 'vote vs 1-NN' rows ${n_vote}, not 3 each:\n"
                        "${out_${run}}")
  endif()
  foreach(i RANGE 2)
    list(GET stc_rows ${i} s)
    list(GET vote_rows ${i} v)
    string(REGEX MATCHALL "[0-9]+/[0-9]+" s_splits "${s}")
    string(REGEX MATCHALL "[0-9]+/[0-9]+" v_splits "${v}")
    if(NOT s_splits STREQUAL v_splits)
      message(FATAL_ERROR "${run}, force set ${i}: the STC's pairing with the 1-NN (${s_splits}) is not the "
                          "one-member vote's (${v_splits}):\n${out_${run}}")
    endif()
  endforeach()
endforeach()
