# tools/plot/stop_threshold_curve.py on the test logs (tests/data/robot: 3 good, 3 missed, 3
# caught synthetic trials) with the test model, which stops all three caught trials and no other
# at its own policy (ReplayCli.LogsFolderTalliesTheStopsPerOutcome). Checked from its JSON:
#  - at 0.9, the predictor's tally: 3/3 caught, nothing else, so 0 stopped for nothing and
#    91/360 x 100 = 25.3 catches per 100 pulls;
#  - a higher threshold never stops more pulls of any kind (the posterior is the same; only the
#    bar it must clear rises);
#  - these logs hold no middle-arm miss, and the tool says so;
#  - without --consecutive every threshold keeps the model's own stop_consecutive (it passed 5
#    whatever the model said).
# Plus its error for a model that is not there.
file(MAKE_DIRECTORY ${WORK})
execute_process(COMMAND /usr/bin/python3 ${SRC}/tools/plot/stop_threshold_curve.py ${WORK}/curve.png
                        --dressguard ${DG} --model ${MODEL} --logs ${SRC}/tests/data/robot
                        --thresholds 0.5,0.9,0.999,0.999999 --json ${WORK}/curve.json
                RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT rc EQUAL 0 OR NOT EXISTS ${WORK}/curve.png)
  message(FATAL_ERROR "stop_threshold_curve.py failed (${rc}): ${out} ${err}")
endif()
if(NOT out MATCHES "no logs of: middle missed")
  message(FATAL_ERROR "the missing middle-arm misses are not flagged: ${out}")
endif()
file(READ ${WORK}/curve.json j)
execute_process(COMMAND ${DG} model show ${MODEL} --json RESULT_VARIABLE rc OUTPUT_VARIABLE model_json)
string(JSON own GET "${model_json}" stop_consecutive)
string(JSON used ERROR_VARIABLE json_err GET "${j}" consecutive)
string(JSON from ERROR_VARIABLE json_err GET "${j}" consecutive_from)
if(NOT rc EQUAL 0 OR NOT used EQUAL own OR NOT from STREQUAL "model" OR NOT out MATCHES "stop_consecutive ${own} \\(the model's\\)")
  message(FATAL_ERROR "without --consecutive: ${used} from '${from}', the model's own is ${own} (${rc}): ${out}")
endif()
string(JSON n LENGTH "${j}" points)
if(NOT n EQUAL 4)
  message(FATAL_ERROR "expected 4 points, got ${n}: ${j}")
endif()
set(previous "")
math(EXPR last "${n} - 1")
foreach(i RANGE ${last})
  string(JSON t GET "${j}" points ${i} threshold)
  set(row "")
  foreach(kind good "low missed" caught)
    string(JSON s GET "${j}" points ${i} stops "${kind}" 0)
    string(JSON total GET "${j}" points ${i} stops "${kind}" 1)
    if(NOT total EQUAL 3)
      message(FATAL_ERROR "threshold ${t}: ${total} '${kind}' logs, expected 3")
    endif()
    list(APPEND row ${s})
  endforeach()
  if(t EQUAL 0.9)
    string(JSON nothing GET "${j}" points ${i} stopped_for_nothing_per_100)
    string(JSON catches GET "${j}" points ${i} catches_stopped_per_100)
    if(NOT row STREQUAL "0;0;3" OR NOT nothing EQUAL 0 OR catches LESS 25.27 OR catches GREATER 25.28)
      message(FATAL_ERROR "at 0.9: stops good;low missed;caught = ${row}, ${nothing} for nothing, ${catches} catches per 100")
    endif()
  endif()
  if(previous)
    foreach(k RANGE 2)
      list(GET row ${k} now)
      list(GET previous ${k} before)
      if(now GREATER before)
        message(FATAL_ERROR "threshold ${t} stops more (${row}) than the lower one before it (${previous})")
      endif()
    endforeach()
  endif()
  set(previous "${row}")
endforeach()
execute_process(COMMAND /usr/bin/python3 ${SRC}/tools/plot/stop_threshold_curve.py ${WORK}/none.png
                        --dressguard ${DG} --model ${WORK}/no-such.dgm --logs ${SRC}/tests/data/robot
                RESULT_VARIABLE rc ERROR_VARIABLE err OUTPUT_QUIET)
if(rc EQUAL 0 OR NOT err MATCHES "no-such.dgm: no such model")
  message(FATAL_ERROR "a missing model is not named (${rc}): ${err}")
endif()
