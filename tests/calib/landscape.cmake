# tools/bench/bench_calib_landscape: the objective around a shipped calibration. Its baseline
# (the file's point simulated again) must reproduce the recorded L of each sequence to the bit,
# and the scale's row must name each sequence and the combined L; bad options exit 2 by name.
# --points writes every point (the file's first, its steps all zero), a column per searched
# parameter and sequence; tools/plot/surrogate_rank.py, which reads it, must rank objectives of
# known shape as they are (its self-test) before it is trusted on the simulator's.
# -DDG=<dressguard> -DBENCH=<bench_calib_landscape> -DWORK=<dir> -DSTUDY=<study dir or empty>
# -DCAL=<models/participant4-worst.json> -DRANK=<tools/plot/surrogate_rank.py>
file(REMOVE_RECURSE ${WORK})
file(MAKE_DIRECTORY ${WORK})
execute_process(COMMAND /usr/bin/python3 ${RANK} --self-test RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT rc EQUAL 0 OR NOT out MATCHES "quadratic bowl +full quadratic on L +median tau +1\\.000 .* ok\n")
  message(FATAL_ERROR "surrogate_rank.py --self-test (${rc}):\n${out}\n${err}")
endif()
execute_process(COMMAND ${BENCH} --calibration ${CAL} --data ${WORK} --points ${WORK} RESULT_VARIABLE rc ERROR_VARIABLE err)
if(NOT rc EQUAL 2 OR NOT err MATCHES "--points .* is a folder; give a file name")
  message(FATAL_ERROR "bench_calib_landscape with a folder for --points (${rc}): ${err}")
endif()
execute_process(COMMAND ${BENCH} --calibration ${CAL} RESULT_VARIABLE rc ERROR_VARIABLE err)
if(NOT rc EQUAL 2 OR NOT err MATCHES "need --calibration CAL.json and --data DATASET")
  message(FATAL_ERROR "bench_calib_landscape without --data (${rc}): ${err}")
endif()
execute_process(COMMAND ${BENCH} --calibration ${CAL} --data ${WORK} --scales 0.01,2 RESULT_VARIABLE rc ERROR_VARIABLE err)
if(NOT rc EQUAL 2 OR NOT err MATCHES "each scale must be in \\(0, 1\\]")
  message(FATAL_ERROR "bench_calib_landscape with a scale of 2 (${rc}): ${err}")
endif()
if(NOT STUDY)
  message("SKIP: shared/data/kapusta2016-calibration-trials not present; the landscape needs the study")
  return()
endif()
execute_process(COMMAND ${DG} import --study ${STUDY} --out ${WORK}/study RESULT_VARIABLE rc)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "dressguard import (${rc})")
endif()
# One point at 1 % of each box (three simulations of two sequences, about a minute on one core).
execute_process(COMMAND ${BENCH} --calibration ${CAL} --data ${WORK}/study --scales 0.01 --samples 1 --threads 2
                RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT rc EQUAL 0
   OR NOT out MATCHES "note: the file records no boxes \\(written before session 40\\): the steps use the default boxes"
   OR NOT out MATCHES "\n  friction +[0-9.]+ in \\[0, 2\\]\n"
   OR NOT out MATCHES "s4-good-3          L 0\\.2337 \\(recorded 0\\.2337, the same bits\\)"
   OR NOT out MATCHES "s4-miss-2          L 0\\.2341 \\(recorded 0\\.2341, the same bits\\)"
   OR NOT out MATCHES "\n0\\.01      s4-miss-2 +[0-9.]+ +[0-9.]+ +[0-9.]+ +[0-9.]+   [01] of 1\n"
   OR NOT out MATCHES "\n0\\.01      combined +[0-9.]+ +[0-9.]+ +[0-9.]+ +0\\.0000   [01] of 1 below the file's 0\\.2809\n")
  message(FATAL_ERROR "bench_calib_landscape on participant 4 (${rc}):\n${out}\n${err}")
endif()
# A calibration with its own boxes (a bounds file; one generation of 4 on the coarse gown, about
# 20 s): the bench steps within the recorded boxes, not the defaults, and still reproduces the
# file's point to the bit.
file(WRITE ${WORK}/bounds.txt "friction 0.1 1.5\narm_offset -0.03 0.03\n")
execute_process(COMMAND ${DG} calibrate --data ${WORK}/study --participant 4 --out ${WORK}/c.json --gown coarse
                        --generations 1 --population 4 --threads 2 --seed 1 --bounds ${WORK}/bounds.txt
                RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "calibrate with a bounds file (${rc}):\n${out}\n${err}")
endif()
execute_process(COMMAND ${BENCH} --calibration ${WORK}/c.json --data ${WORK}/study --scales 0.01 --samples 1
                        --threads 2 --points ${WORK}/points.csv
                RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT rc EQUAL 0 OR out MATCHES "records no boxes"
   OR NOT out MATCHES "\n  friction +[0-9.]+ in \\[0\\.1, 1\\.5\\]\n"
   OR NOT out MATCHES "\n  arm_offset_high +-?[0-9.e-]+ in \\[-0\\.03, 0\\.03\\]\n"
   OR NOT out MATCHES "\n  stretch +[0-9.e-]+ in \\[0, 1\\]\n"
   OR NOT out MATCHES "s4-miss-2 +L [0-9.]+ \\(recorded [0-9.]+, the same bits\\)")
  message(FATAL_ERROR "bench_calib_landscape on a calibration with its own boxes (${rc}):\n${out}\n${err}")
endif()
file(STRINGS ${WORK}/points.csv rows)
list(LENGTH rows n)
list(GET rows 0 header)
if(NOT n EQUAL 3
   OR NOT header MATCHES "^scale,sample,d_stretch,d_shear,d_bend,d_friction,d_self_friction,d_arm_offset_high,"
   OR NOT header MATCHES ",L_s4-[a-z]+-[0-9]+,L_s4-[a-z]+-[0-9]+,L_combined$")
  message(FATAL_ERROR "bench_calib_landscape --points: ${n} rows, header '${header}'")
endif()
string(REGEX MATCHALL "d_" steps "${header}")
list(LENGTH steps p)
list(GET rows 1 file_point)
list(GET rows 2 step_point)
string(REPEAT ",0" ${p} zeros)
if(NOT file_point MATCHES "^0,0${zeros},[0-9.e-]+,[0-9.e-]+,[0-9.e-]+$" OR NOT step_point MATCHES "^0\\.01,0,")
  message(FATAL_ERROR "bench_calib_landscape --points: the file's point '${file_point}', the step '${step_point}'")
endif()
