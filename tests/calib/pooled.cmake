# tools/bench/bench_calib_pipeline pooled with several seeds: each seed's STC of a file, trained
# on that seed's part of the union, must be the STC a one-seed run trains on the same set (the
# union renumbers seed s's trials from s x per_height), and the seeds' pairing rows must be there
# for the paper's three classes and for good or missed; a seed without its folder exits 2.
# Each STC's pairing with the 1-NN must match the one-member vote's, asked the three classes and
# asked "good or missed?", and its good-or-missed pairing must meet the same 1-NN on the same
# trials; the good-or-missed vote gains no more trials than the plain vote calls caught. The
# run's file keeps both votes' pairings and plots. Trials 0-1 of a 3-per-height set (--indices)
# train the STC a 2-per-height set trains; tools/plot/committee_draws.py draws the runs together.
# A one-member vote's ballots give that member's answer as the vote, and so do its votes weighted
# by rule S or R and read by rule C; tools/plot/member_weights.py draws what the weights see.
# -DBENCH=<bench_calib_pipeline> -DWORK=<dir> -DSTUDY=<study dir or empty> -DCAL=<a calibration>
# -DPLOT=<tools/plot/pooled_stc.py> -DPLOT_DRAWS=<tools/plot/committee_draws.py>
# -DPLOT_WEIGHTS=<tools/plot/member_weights.py>
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
# Likewise each seed's STC asked "good or missed?" with equal priors: the one-seed run's
# "good|missed" rows.
rows("${out_s1}" "good\\|missed" gm_one)
rows("${out_union}" "good\\|missed, seed 1 alone" union_gm_one)
rows("${out_s2}" "good\\|missed" gm_two)
rows("${out_union}" "good\\|missed, seed 2 alone" union_gm_two)
if(NOT gm_one STREQUAL union_gm_one OR NOT gm_two STREQUAL union_gm_two)
  message(FATAL_ERROR "a seed's good-or-missed STC in the union is not its one-seed run's:\nseed 1 ${gm_one}\n"
                      "in the union ${union_gm_one}\nseed 2 ${gm_two}\nin the union ${union_gm_two}")
endif()
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
# so its pairing with the 1-NN (`vote_label`) must give the STC's splits (`stc_label`), force set
# by force set. Sets `out_var` in the caller to the STC's three rows.
set(pair "([0-9]+/[0-9]+)")
function(vote_is_stc text run what stc_label vote_label out_var)
  string(REGEX MATCHALL "\n  ${stc_label}: ${stem} +- +${cell} ${cell} ${cell} ${cell}\n" stc "${text}")
  string(REGEX MATCHALL "\n  ${vote_label}: only vote / only 1-NN +- +${pair} +${pair} +${pair} +${pair}\n" vote
         "${text}")
  list(LENGTH stc n_stc)
  list(LENGTH vote n_vote)
  if(NOT n_stc EQUAL 3 OR NOT n_vote EQUAL 3)
    message(FATAL_ERROR "${run}: '${stc_label}' rows ${n_stc}, '${vote_label}' rows ${n_vote}, not 3 each:\n${text}")
  endif()
  foreach(i RANGE 2)
    list(GET stc ${i} s)
    list(GET vote ${i} v)
    string(REGEX MATCHALL "[0-9]+/[0-9]+" s_splits "${s}")
    string(REGEX MATCHALL "[0-9]+/[0-9]+" v_splits "${v}")
    if(NOT s_splits STREQUAL v_splits)
      message(FATAL_ERROR "${run}, force set ${i}: the STC's ${what} pairing with the 1-NN (${s_splits}) is not "
                          "the one-member vote's (${v_splits}):\n${text}")
    endif()
  endforeach()
  set(${out_var} "${stc}" PARENT_SCOPE)
endfunction()
foreach(run s1 s2)
  vote_is_stc("${out_${run}}" ${run} "three-class" "STC vs 1-NN, b/c p" "vote vs 1-NN, paired" stc_rows)
  vote_is_stc("${out_${run}}" ${run} "good-or-missed" "good\\|missed vs 1-NN, b/c p" "vote good\\|missed vs 1-NN"
              gm_rows)
  # The same STC asked "good or missed?", paired with the same 1-NN on the same trials: b - c is
  # the STC's count less the 1-NN's, so (b - c) of the good-or-missed row less (b - c) of the
  # three-class row must be the two rows' difference in trials right, cut by cut. It fails when
  # either pairing meets another 1-NN or other trials.
  rows("${out_${run}}" "alone" three)
  rows("${out_${run}}" "good\\|missed" gm)
  foreach(i RANGE 2)
    foreach(what three gm stc_rows gm_rows)
      list(GET ${what} ${i} row_${what})
    endforeach()
    string(REGEX MATCH "\\(([0-9]+) trials\\)" unused "${row_three}")
    set(n_trials ${CMAKE_MATCH_1})
    string(REGEX MATCHALL "[0-9]+%" p_three "${row_three}")
    string(REGEX MATCHALL "[0-9]+%" p_gm "${row_gm}")
    string(REGEX MATCHALL "[0-9]+/[0-9]+" s_three "${row_stc_rows}")
    string(REGEX MATCHALL "[0-9]+/[0-9]+" s_gm "${row_gm_rows}")
    foreach(c RANGE 1 4)
      list(GET p_three ${c} a)
      list(GET p_gm ${c} g)
      math(EXPR cm1 "${c} - 1")
      list(GET s_three ${cm1} x)
      list(GET s_gm ${cm1} y)
      string(REPLACE "%" "" a "${a}")
      string(REPLACE "%" "" g "${g}")
      string(REPLACE "/" ";" x "${x}")
      string(REPLACE "/" ";" y "${y}")
      list(GET x 0 xb)
      list(GET x 1 xc)
      list(GET y 0 yb)
      list(GET y 1 yc)
      # Percentages back to trials: printed to 1 %, so exact for fewer than 100 trials.
      math(EXPR right_three "(${a} * ${n_trials} + 50) / 100")
      math(EXPR right_gm "(${g} * ${n_trials} + 50) / 100")
      math(EXPR lhs "(${yb} - ${yc}) - (${xb} - ${xc})")
      math(EXPR rhs "${right_gm} - ${right_three}")
      if(NOT lhs EQUAL rhs)
        message(FATAL_ERROR "${run}, force set ${i}, cut ${c}: the good-or-missed pairing with the 1-NN "
                            "(${yb}/${yc}) and the three-class one (${xb}/${xc}) differ by ${lhs}, the rows by "
                            "${rhs} trials:\n${out_${run}}")
      endif()
    endforeach()
  endforeach()
endforeach()
# The vote's trials called caught: a trial the plain vote does not call caught keeps its answer
# when each STC is asked "good or missed?" (one member: the larger of two is the larger of three),
# so the good-or-missed vote is right on no fewer trials and on at most as many more as the plain
# vote calls caught, whole and at each cut.
set(label_plain "vote of the other people's STCs")
set(label_caught "vote: trials it calls caught")
set(label_gm "vote, each asked good or missed only")
foreach(run s1 s2)
  foreach(what plain caught gm)
    string(REGEX MATCHALL "\n  ${label_${what}} +[0-9% ]+\\([0-9]+ trials\\)" ${what} "${out_${run}}")
    list(LENGTH ${what} n)
    if(NOT n EQUAL 3)
      message(FATAL_ERROR "${run}: '${label_${what}}' found ${n} times, not 3:\n${out_${run}}")
    endif()
  endforeach()
  foreach(i RANGE 2)
    foreach(what plain caught gm)
      list(GET ${what} ${i} row)
      string(REGEX MATCH "\\(([0-9]+) trials\\)" unused "${row}")
      set(n_trials ${CMAKE_MATCH_1})
      string(REGEX MATCHALL "[0-9]+%" pct_${what} "${row}")
    endforeach()
    foreach(c RANGE 4)
      foreach(what plain caught gm)
        list(GET pct_${what} ${c} v)
        string(REPLACE "%" "" v "${v}")
        math(EXPR k_${what} "(${v} * ${n_trials} + 50) / 100")
      endforeach()
      math(EXPR gain "${k_gm} - ${k_plain}")
      if(gain LESS 0 OR gain GREATER k_caught)
        message(FATAL_ERROR "${run}, force set ${i}, column ${c}: the good-or-missed vote is right on ${gain} "
                            "trials more than the plain vote, which calls ${k_caught} caught:\n${out_${run}}")
      endif()
    endforeach()
  endforeach()
endforeach()
# The file keeps both votes' pairings with the 1-NN (four cuts each), and the accuracy plot
# (tools/plot/pooled_stc.py) draws it.
file(READ ${WORK}/s1/pooled.json json)
foreach(key vote_against_one_nn_at_cuts vote_good_or_missed_against_one_nn_at_cuts)
  string(JSON n ERROR_VARIABLE json_err LENGTH "${json}" force_sets 0 ${key})
  if(NOT n EQUAL 4)
    message(FATAL_ERROR "${WORK}/s1/pooled.json: ${key} holds ${n} cuts, not 4 ${json_err}")
  endif()
endforeach()
execute_process(COMMAND /usr/bin/python3 ${PLOT} ${WORK}/s1/pooled.json ${WORK}/pooled.png
                RESULT_VARIABLE rc ERROR_VARIABLE err)
if(NOT rc EQUAL 0 OR NOT EXISTS ${WORK}/pooled.png)
  message(FATAL_ERROR "pooled_stc.py on ${WORK}/s1/pooled.json (${rc}): ${err}")
endif()
# --indices: a synthesized trial is a function of the seed, the height and its index (its speed
# of index < per_height / 2), so trials 0 and 1 of seed 1's 3-per-height set are a 2-per-height
# set's, and the STC trained on them alone (--indices 0-1) must be that set's STC, each force set,
# asked the three classes and good or missed. Six more simulations. A range past the set, or
# one that is not two whole numbers, exits 2 naming it.
foreach(bad 1-3 1x-2)
  execute_process(COMMAND ${BENCH} ${common} --seed 1 --synth ${WORK}/s1 --indices ${bad} RESULT_VARIABLE rc
                  OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT rc EQUAL 2 OR NOT err MATCHES "pooled: --indices: '${bad}' is not a range A-B with 0 <= A <= B < 3")
    message(FATAL_ERROR "pooled --indices ${bad} of 3 per height (${rc}):\n${out}\n${err}")
  endif()
endforeach()
execute_process(COMMAND ${BENCH} pooled --calibrations ${CAL} --per-height 2 --threads 2 --seed 1 --synth ${WORK}/two
                RESULT_VARIABLE rc OUTPUT_VARIABLE out_two ERROR_VARIABLE err)
execute_process(COMMAND ${BENCH} ${common} --seed 1 --synth ${WORK}/s1 --indices 0-1 RESULT_VARIABLE rc_sub
                OUTPUT_VARIABLE out_sub ERROR_VARIABLE err_sub)
if(NOT rc EQUAL 0 OR NOT rc_sub EQUAL 0)
  message(FATAL_ERROR "pooled at 2 per height (${rc}) or --indices 0-1 (${rc_sub}):\n${out_two}\n${err}\n${err_sub}")
endif()
foreach(label "alone" "good\\|missed")
  rows("${out_two}" "${label}" whole_set)
  rows("${out_sub}" "${label}" subset)
  if(NOT whole_set STREQUAL subset)
    message(FATAL_ERROR "'${label}': the STC of trials 0-1 of 3 per height (${subset}) is not the 2-per-height "
                        "set's (${whole_set}):\n${out_sub}")
  endif()
endforeach()
file(READ ${WORK}/s1/pooled-0-1.json json)
string(JSON n_sub ERROR_VARIABLE json_err GET "${json}" per_height)
string(JSON range ERROR_VARIABLE json_err GET "${json}" indices 0)
if(NOT n_sub EQUAL 2 OR NOT range STREQUAL "0-1")
  message(FATAL_ERROR "${WORK}/s1/pooled-0-1.json: per_height ${n_sub}, indices '${range}' (want 2, '0-1') "
                      "${json_err}")
endif()
# tools/plot/committee_draws.py draws the runs' votes side by side (two seeds and the subset),
# and names the file that lacks a vote's accuracies.
execute_process(COMMAND /usr/bin/python3 ${PLOT_DRAWS} ${WORK}/s1/pooled.json ${WORK}/s2/pooled.json
                        ${WORK}/s1/pooled-0-1.json ${WORK}/draws.png RESULT_VARIABLE rc ERROR_VARIABLE err)
if(NOT rc EQUAL 0 OR NOT EXISTS ${WORK}/draws.png)
  message(FATAL_ERROR "committee_draws.py on three runs (${rc}): ${err}")
endif()
file(WRITE ${WORK}/no-vote.json "{\"seed\": 1, \"per_height\": 2, \"force_sets\": [{\"forces\": \"F_motion\"}]}")
execute_process(COMMAND /usr/bin/python3 ${PLOT_DRAWS} ${WORK}/no-vote.json ${WORK}/no-vote.png RESULT_VARIABLE rc
                ERROR_VARIABLE err)
if(NOT rc EQUAL 1 OR NOT err MATCHES "no-vote.json: force set 'F_motion' has no vote_accuracy_whole_and_cuts")
  message(FATAL_ERROR "committee_draws.py on a file without the vote (${rc}): ${err}")
endif()
# Each trial's ballot (vote_ballots_whole_and_cuts): with one member the vote is that member's
# answer, trial by trial, in every column of the first force set; every ballot names its label,
# and at the cuts as many ballots are right as the vote's pairing with the 1-NN counts.
file(READ ${WORK}/s1/pooled.json json)
string(JSON n_cols ERROR_VARIABLE json_err LENGTH "${json}" force_sets 0 vote_ballots_whole_and_cuts)
if(NOT n_cols EQUAL 5)
  message(FATAL_ERROR "${WORK}/s1/pooled.json: vote_ballots_whole_and_cuts holds ${n_cols} columns, not 5 ${json_err}")
endif()
foreach(c RANGE 4)
  string(JSON n_ballots LENGTH "${json}" force_sets 0 vote_ballots_whole_and_cuts ${c})
  if(n_ballots LESS 1)
    message(FATAL_ERROR "${WORK}/s1/pooled.json: no ballot in column ${c}")
  endif()
  math(EXPR last "${n_ballots} - 1")
  set(right 0)
  foreach(i RANGE ${last})
    string(JSON ballot GET "${json}" force_sets 0 vote_ballots_whole_and_cuts ${c} ${i})
    string(JSON trial GET "${ballot}" trial)
    string(JSON label GET "${ballot}" label)
    string(JSON vote GET "${ballot}" vote)
    string(JSON answer ERROR_VARIABLE json_err GET "${ballot}" members ${stem})
    if(NOT vote STREQUAL answer OR NOT label MATCHES "^(good|missed)$")
      message(FATAL_ERROR "${WORK}/s1/pooled.json, column ${c}, ${trial} (${label}): the vote '${vote}' is not its "
                          "one member's answer '${answer}' ${json_err}")
    endif()
    if(vote STREQUAL label)
      math(EXPR right "${right} + 1")
    endif()
  endforeach()
  if(c GREATER 0)
    math(EXPR k "${c} - 1")
    string(JSON counted GET "${json}" force_sets 0 vote_against_one_nn_at_cuts ${k} vote_right)
    if(NOT right EQUAL counted)
      message(FATAL_ERROR "${WORK}/s1/pooled.json, cut ${k}: ${right} ballots right, the vote's pairing counts "
                          "${counted}")
    endif()
  endif()
endforeach()
# The weighted votes (rules S and R, session 73): with one member, whatever its weight (rule S
# gives it none, there being no other simulator; rule R its log-odds on the measured trials), the
# decision is that member's answer, so each weighted vote is right on the same trials as the
# plain vote of its question, in every column of every force set. So is rule C's (session 74):
# with no other simulator to count its answers on, its answer model says nothing and the tie
# goes to the larger posterior sum, the member's own answer.
string(JSON n_sets LENGTH "${json}" force_sets)
math(EXPR last_set "${n_sets} - 1")
foreach(f RANGE ${last_set})
  foreach(rule weighted_simulated weighted_measured answer_models_simulated)
    foreach(q "" "_good_or_missed")
      string(JSON weighted ERROR_VARIABLE json_err GET "${json}" force_sets ${f}
             vote_${rule}${q}_accuracy_whole_and_cuts)
      string(JSON plain GET "${json}" force_sets ${f} vote${q}_accuracy_whole_and_cuts)
      string(JSON b ERROR_VARIABLE json_err2 GET "${json}" force_sets ${f} vote_${rule}${q}_against_vote
             only_first_right_whole_and_cuts)
      string(JSON c GET "${json}" force_sets ${f} vote_${rule}${q}_against_vote only_second_right_whole_and_cuts)
      string(REGEX REPLACE "[ \n]" "" b "${b}")
      string(REGEX REPLACE "[ \n]" "" c "${c}")
      if(NOT weighted STREQUAL plain OR NOT b STREQUAL "[0,0,0,0,0]" OR NOT c STREQUAL "[0,0,0,0,0]")
        message(FATAL_ERROR "${WORK}/s1/pooled.json, force set ${f}: the one-member vote weighted by rule "
                            "'${rule}${q}' (${weighted}; only it / only the plain vote right ${b} ${c}) is not the "
                            "plain vote (${plain}) ${json_err} ${json_err2}")
      endif()
    endforeach()
  endforeach()
  string(JSON w GET "${json}" force_sets ${f} vote_weights 0 simulated_three_classes 0 whole_and_cuts)
  string(REGEX REPLACE "[ \n]" "" w "${w}")
  if(NOT w STREQUAL "[0,0,0,0,0]")
    message(FATAL_ERROR "${WORK}/s1/pooled.json, force set ${f}: a lone member's rule-S weights are ${w}, not 0")
  endif()
  string(JSON n GET "${json}" force_sets ${f} vote_weights 0 answer_models_good_or_missed 0
         answer_counts_whole_and_cuts)
  string(REGEX REPLACE "[ \n]" "" n "${n}")
  if(NOT n STREQUAL "[[[0,0],[0,0]],[[0,0],[0,0]],[[0,0],[0,0]],[[0,0],[0,0]],[[0,0],[0,0]]]")
    message(FATAL_ERROR "${WORK}/s1/pooled.json, force set ${f}: a lone member's rule-C counts are ${n}, not 0")
  endif()
endforeach()
# What the weights see, drawn; a file from before session 73 (no member on other simulators) is
# named.
execute_process(COMMAND /usr/bin/python3 ${PLOT_WEIGHTS} ${WORK}/s1/pooled.json ${WORK}/weights.png
                RESULT_VARIABLE rc ERROR_VARIABLE err)
if(NOT rc EQUAL 0 OR NOT EXISTS ${WORK}/weights.png)
  message(FATAL_ERROR "member_weights.py (${rc}): ${err}")
endif()
execute_process(COMMAND /usr/bin/python3 ${PLOT_WEIGHTS} ${WORK}/no-vote.json ${WORK}/no-weights.png
                RESULT_VARIABLE rc ERROR_VARIABLE err)
if(NOT rc EQUAL 1 OR NOT err MATCHES "no-vote.json: force set 'F_motion' has no single_on_other_simulators")
  message(FATAL_ERROR "member_weights.py on a file without the members' rows (${rc}): ${err}")
endif()
