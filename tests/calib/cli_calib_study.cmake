# The calibrate / synthesize / build-model / predict commands on the study's measured trials
# (import, bounds, calibration files, rescoring, the discrepancy term). Skipped, saying so, where
# shared/data is not present.
# -DDG=<dressguard> -DWORK=<dir> -DSTUDY=<study dir or empty> -DHMM=<0|1> -DPLOT=<calib_overlay.py>
include(${CMAKE_CURRENT_LIST_DIR}/cli_common.cmake)
if(NOT STUDY)
  message("SKIP: shared/data/kapusta2016-calibration-trials not present; these commands need the study")
  return()
endif()
file(REMOVE_RECURSE ${WORK})
file(MAKE_DIRECTORY ${WORK})
write_cal4(${WORK}/cal4.json)
execute_process(COMMAND ${DG} import --study ${STUDY} --out ${WORK}/study RESULT_VARIABLE rc)
# The people's outcomes over travel in all three forces, as a picture.
execute_process(COMMAND /usr/bin/python3 ${PLOT} classes ${WORK}/study --out ${WORK}/classes.png
                RESULT_VARIABLE rc ERROR_VARIABLE err)
if(NOT rc EQUAL 0 OR NOT EXISTS ${WORK}/classes.png)
  message(FATAL_ERROR "calib_overlay.py classes on the study (${rc}): ${err}")
endif()
file(WRITE ${WORK}/bounds.txt "friction 0 2\nstiffness 0 1\n")
expect_fail("calibrate with a bad bounds file" "bounds.txt:2: unknown parameter 'stiffness'"
            calibrate --data ${WORK}/study --participant 4 --out ${WORK}/c.json --bounds ${WORK}/bounds.txt)
# An arm offset box no calibration file can hold (read_calibration refuses beyond 0.5 m).
file(WRITE ${WORK}/bounds-arm.txt "arm_offset 0.6 0.9\n")
expect_fail("calibrate with an arm offset box beyond 0.5 m" "bounds-arm.txt:1: arm_offset must lie within +-0.5 m"
            calibrate --data ${WORK}/study --participant 4 --out ${WORK}/c.json --bounds ${WORK}/bounds-arm.txt)
# A search CMA-ES ends on one of its own criteria says which, and that the budget was not used
# (sigma0 1e-300: no step moves the mean; ~15 s on the coarse gown). It once said nothing.
execute_process(COMMAND ${DG} calibrate --data ${WORK}/study --participant 4 --gown coarse --generations 5
                        --population 4 --sigma0 1e-300 --out ${WORK}/tiny.json
                RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT rc EQUAL 0 OR NOT out MATCHES "after 1 generations"
   OR NOT out MATCHES "CMA-ES stopped on its own criterion \\([a-z-]+\\) before the budget of 5 generations")
  message(FATAL_ERROR "calibrate stopped by CMA-ES (${rc}):\n${out}\n${err}")
endif()
expect_fail("calibrate an absent participant" "participant '42'" calibrate --data ${WORK}/study --participant 42 --out ${WORK}/c.json)
expect_fail("calibrate --inputs with another person's trial"
            "--inputs: trial 's1-miss-1' is participant 1's, not 4's (${WORK}/study/manifest.csv)"
            calibrate --data ${WORK}/study --participant 4 --out ${WORK}/c.json --inputs s4-good-3,s1-miss-1)
expect_fail("calibrate --inputs with two trials at one height" "--inputs: trials 's1-good-1' and 's1-good-3' are both at the high arm"
            calibrate --data ${WORK}/study --participant 1 --out ${WORK}/c.json --inputs s1-good-1,s1-good-3)
expect_fail("calibrate --inputs naming no trial" "--inputs must name one to three trial ids, not ','"
            calibrate --data ${WORK}/study --participant 4 --out ${WORK}/c.json --inputs ,)
# One generation of 4 on the coarse gown (~10 s), the density and the arm's side fitted too, the
# heights' contrast and the lateral force in the objective: the calibration file (its searched
# parameters end with the density and the arm's side; both terms' weights and values; each
# sequence's lateral fit) and its curves, the fitted values and both terms on stdout, and a
# progress line with the best point's L and each sequence's and each term's share of it.
execute_process(COMMAND ${DG} calibrate --data ${WORK}/study --participant 4 --out ${WORK}/c1.json --gown coarse
                        --generations 1 --population 4 --threads 2 --seed 1 --density fit --contrast-weight 5
                        --arm-lateral fit --lateral-weight 3
                RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(EXISTS ${WORK}/c1.json)
  file(READ ${WORK}/c1.json c1)
endif()
if(NOT rc EQUAL 0 OR NOT EXISTS ${WORK}/c1.json OR NOT EXISTS ${WORK}/c1.json.curves.csv
   OR NOT c1 MATCHES "\"parameters\": \\[[^]]*\"arm_offset_low\", \"areal_density\", \"arm_lateral\"\\]"
   OR NOT c1 MATCHES "\\[0\\.04[0-9]*, 0\\.25\\],\n +\\[-0\\.05[0-9]*, 0\\.05[0-9]*\\]\n +\\]"
   OR NOT c1 MATCHES "\"contrast_weight\": 5,\n  \"contrast\": [0-9.e-]+,\n  \"lateral_weight\": 3,\n  \"lateral\": [0-9]"
   OR NOT c1 MATCHES "\"lateral_error\": [0-9.e-]+,\n      \"lateral_zero\": [0-9]"
   OR NOT out MATCHES "\n  areal_density +0\\.[0-9]+\n  arm_lateral +-?0\\.[0-9]+\n"
   OR NOT out MATCHES "\n  the heights' contrast to 0.30 m: [0-9.]+ N m, times 5: [0-9.]+ of L\n"
   OR NOT out MATCHES "\n  the lateral force over the common travel: [0-9.]+ N m, times 3: [0-9.]+ of L\n"
   OR NOT err MATCHES "generation 1/1  best L [0-9.]+ \\(s4-good-3 [0-9.]+, s4-miss-2 [0-9.]+, contrast [0-9.]+, lateral [0-9.]+\\)  \\(this generation")
  message(FATAL_ERROR "calibrate on the coarse gown (${rc}):\n${out}\n${err}")
endif()
# Pruned (--prune): from the second generation on its progress lines say how many candidates
# were cut and finished whole after all, each line the cloth time simulated, and the file
# records the factor, the counts and the cloth time.
execute_process(COMMAND ${DG} calibrate --data ${WORK}/study --participant 4 --out ${WORK}/c1p.json --gown coarse
                        --generations 2 --population 4 --threads 2 --seed 1 --prune 1
                RESULT_VARIABLE rc OUTPUT_VARIABLE pout ERROR_VARIABLE perr)
if(EXISTS ${WORK}/c1p.json)
  file(READ ${WORK}/c1p.json c1p)
endif()
if(NOT rc EQUAL 0 OR NOT EXISTS ${WORK}/c1p.json
   OR NOT perr MATCHES "generation 1/2  best L [^\n]*\\(this generation [0-9.]+\\)  pruned 0/4 \\(0 again\\)  elapsed"
   OR NOT perr MATCHES "generation 2/2  best L [^\n]*  pruned [0-4]/4 \\([0-4] again\\)  elapsed [^\n]*  ETA [^\n]*  [1-9][0-9]* s of cloth simulated\n"
   OR NOT c1p MATCHES "\"prune\": 1,\n +\"pruned_last_process\": [0-9]+,\n +\"resimulated_last_process\": [0-9]+"
   OR NOT c1p MATCHES "\"simulated_s_last_process\": [1-9]")
  message(FATAL_ERROR "calibrate --prune on the coarse gown (${rc}):\n${pout}\n${perr}")
endif()
# Its progress as a picture (tools/plot/calib_overlay.py progress reads the kept stderr).
file(WRITE ${WORK}/c1.log "${err}")
execute_process(COMMAND /usr/bin/python3 ${PLOT} progress ${WORK}/c1.log --out ${WORK}/c1-progress.png
                RESULT_VARIABLE rc ERROR_VARIABLE err)
if(NOT rc EQUAL 0 OR NOT EXISTS ${WORK}/c1-progress.png)
  message(FATAL_ERROR "calib_overlay.py progress on calibrate's log (${rc}): ${err}")
endif()
# Scored again by this build (calibrate --rescore): a file this build just wrote keeps every
# figure to its last digit (the objective, each sequence's L and axis fits, both terms); the
# provenance gains what it replaced and why. Bad input names the file.
execute_process(COMMAND ${DG} calibrate --rescore ${WORK}/c1.json --data ${WORK}/study --out ${WORK}/c1r.json
                        --why "a test"
                RESULT_VARIABLE rrc OUTPUT_VARIABLE rout ERROR_VARIABLE rerr)
if(EXISTS ${WORK}/c1r.json)
  file(READ ${WORK}/c1r.json c1r)
  string(REGEX REPLACE ",\n +\"rescored\": \\[.*\\]\n  }\n}\n$" "\n  }\n}\n" c1r_unrescored "${c1r}")
endif()
if(NOT rrc EQUAL 0 OR NOT EXISTS ${WORK}/c1r.json.curves.csv OR NOT c1r_unrescored STREQUAL c1
   OR NOT c1r MATCHES "\"rescored\": \\[\n +{\n +\"when\": \"[0-9T:Z-]+\",\n +\"why\": \"a test\",\n +\"before\": {\n +\"objective\": [0-9]"
   OR NOT rout MATCHES "participant 4: L = ([0-9.]+) \\(recorded ([0-9.]+)\\)\n  s4-good-3 "
   OR NOT CMAKE_MATCH_1 STREQUAL CMAKE_MATCH_2)
  message(FATAL_ERROR "calibrate --rescore on a file of this build (${rrc}):\n${rout}\n${rerr}")
endif()
# Under another friction scheme (--friction constraint; coarse gown, 1 x 4, ~20 s): the run says
# so, the file records it, and --rescore simulates under it, so the file's own figure comes back
# to its last digit; the same file with the scheme taken out (the improved one) scores another L.
execute_process(COMMAND ${DG} calibrate --data ${WORK}/study --participant 4 --out ${WORK}/cf.json --gown coarse
                        --generations 1 --population 4 --threads 2 --seed 1 --friction constraint
                RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(EXISTS ${WORK}/cf.json)
  file(READ ${WORK}/cf.json cf)
endif()
if(NOT rc EQUAL 0 OR NOT cf MATCHES "\"friction_scheme\": \"constraint\""
   OR NOT err MATCHES "gown coarse, friction constraint\n" OR NOT out MATCHES "\n  friction      the constraint scheme \\(held\\)\n")
  message(FATAL_ERROR "calibrate --friction constraint (${rc}):\n${out}\n${err}")
endif()
string(REGEX REPLACE ",\n +\"friction_scheme\": \"constraint\"" "" cf_improved "${cf}")
file(WRITE ${WORK}/cf-improved.json "${cf_improved}")
foreach(f cf cf-improved)
  execute_process(COMMAND ${DG} calibrate --rescore ${WORK}/${f}.json --data ${WORK}/study --out ${WORK}/${f}-r.json
                  RESULT_VARIABLE rc OUTPUT_VARIABLE out_${f} ERROR_VARIABLE err)
  if(NOT rc EQUAL 0 OR NOT out_${f} MATCHES "participant 4: L = ([0-9.]+) \\(recorded ([0-9.]+)\\)")
    message(FATAL_ERROR "calibrate --rescore ${f}.json (${rc}):\n${out_${f}}\n${err}")
  endif()
  set(now_${f} ${CMAKE_MATCH_1})
  set(was_${f} ${CMAKE_MATCH_2})
endforeach()
if(NOT now_cf STREQUAL was_cf OR now_cf-improved STREQUAL was_cf-improved)
  message(FATAL_ERROR "rescore under the file's friction scheme: ${now_cf} (recorded ${was_cf}); the same "
                      "values under the improved scheme ${now_cf-improved} (recorded ${was_cf-improved})")
endif()
expect_fail("rescore a missing file" "--rescore ${WORK}/none.json" calibrate --rescore ${WORK}/none.json --data ${WORK}/study --out ${WORK}/x.json)
expect_fail("rescore with a calibrate option" "--participant" calibrate --rescore ${WORK}/c1.json --data ${WORK}/study --out ${WORK}/x.json --participant 4)
# Its curves (with F_lateral since 2026-11-25) overlaid on the measured ones.
file(STRINGS ${WORK}/c1.json.curves.csv header LIMIT_COUNT 1)
execute_process(COMMAND /usr/bin/python3 ${PLOT} fit ${WORK}/c1.json.curves.csv --out ${WORK}/c1-fit.png
                RESULT_VARIABLE rc ERROR_VARIABLE err)
if(NOT header STREQUAL "trial_id,height,source,travel,f_motion,f_vertical,f_lateral" OR NOT rc EQUAL 0
   OR NOT EXISTS ${WORK}/c1-fit.png)
  message(FATAL_ERROR "calib_overlay.py fit on calibrate's curves (${rc}, header '${header}'): ${err}")
endif()
# Stopped after its first generation and run again (coarse gown, 2 x 4, ~30 s for the three
# runs): the start names the checkpoint and whether it resumes it, the resumed process says
# where it took over, the checkpoint is gone at the end, and the file's objective has every
# digit of an uninterrupted run's (the resume is exact; calib_driver_test checks the bits).
set(again calibrate --data ${WORK}/study --participant 4 --gown coarse --generations 2 --population 4
          --threads 2 --seed 3)
execute_process(COMMAND ${DG} ${again} --out ${WORK}/r.json --stop-after-generations 1
                RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT rc EQUAL 0 OR EXISTS ${WORK}/r.json OR NOT EXISTS ${WORK}/r.json.ckpt
   OR NOT out MATCHES "stopped after 1 generations; run the same command again to resume from [^\n]*/r\\.json\\.ckpt"
   OR NOT err MATCHES "calibrate: checkpoint [^\n]*/r\\.json\\.ckpt \\(new: written each generation\\)\n"
   OR err MATCHES "resumed after")
  message(FATAL_ERROR "calibrate stopped after one generation (${rc}):\n${out}\n${err}")
endif()
# Another person's command pointed at that checkpoint is refused before anything is simulated,
# and the checkpoint survives (the resume below reads it). Its --start file is participant 1's,
# fitted to s1-good-3 and s1-miss-1, and its seed selects another good trial: said first.
execute_process(COMMAND ${DG} calibrate --data ${WORK}/study --participant 1 --out ${WORK}/p1.json --gown coarse
                        --start ${CMAKE_CURRENT_LIST_DIR}/../../models/participant1-worst.json --seed 3
                        --checkpoint ${WORK}/r.json.ckpt
                RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(rc EQUAL 0 OR EXISTS ${WORK}/p1.json OR NOT EXISTS ${WORK}/r.json.ckpt
   OR NOT err MATCHES "calibrate: note: --start [^\n]*participant1-worst\\.json was fitted to s1-good-3, s1-miss-1; seed 3 selects s1-good-1, s1-miss-1 \\(--inputs s1-good-3,s1-miss-1 fits those\\)\n"
   OR NOT err MATCHES "r\\.json\\.ckpt:2: checkpoint belongs to a different calibration")
  message(FATAL_ERROR "calibrate with another calibration's checkpoint (${rc}):\n${out}\n${err}")
endif()
# The same with the file's own trials named (--inputs, in either order): seed 3 no longer
# chooses them, so the header lists them in height order and nothing needs saying.
execute_process(COMMAND ${DG} calibrate --data ${WORK}/study --participant 1 --out ${WORK}/p1.json --gown coarse
                        --start ${CMAKE_CURRENT_LIST_DIR}/../../models/participant1-worst.json --seed 3
                        --inputs s1-miss-1,s1-good-3 --checkpoint ${WORK}/r.json.ckpt
                RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(rc EQUAL 0 OR EXISTS ${WORK}/p1.json OR NOT EXISTS ${WORK}/r.json.ckpt OR err MATCHES "note:"
   OR NOT err MATCHES "calibrate: participant 1, 2 sequences \\(s1-good-3, s1-miss-1\\)"
   OR NOT err MATCHES "r\\.json\\.ckpt:2: checkpoint belongs to a different calibration")
  message(FATAL_ERROR "calibrate --inputs with another calibration's checkpoint (${rc}):\n${out}\n${err}")
endif()
# Other trials named than the file's: said, without a seed to blame.
execute_process(COMMAND ${DG} calibrate --data ${WORK}/study --participant 1 --out ${WORK}/p1.json --gown coarse
                        --start ${CMAKE_CURRENT_LIST_DIR}/../../models/participant1-worst.json
                        --inputs s1-good-1,s1-miss-1 --checkpoint ${WORK}/r.json.ckpt
                RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(rc EQUAL 0 OR EXISTS ${WORK}/p1.json OR NOT EXISTS ${WORK}/r.json.ckpt
   OR NOT err MATCHES "calibrate: note: --start [^\n]*participant1-worst\\.json was fitted to s1-good-3, s1-miss-1; --inputs names s1-good-1, s1-miss-1\n")
  message(FATAL_ERROR "calibrate --inputs naming other trials than --start's (${rc}):\n${out}\n${err}")
endif()
# The same command on data changed in place (participant 4's forces; the same trials, the same
# lengths): refused, as the checkpoint holds the samples' hash (it once resumed on ids and
# lengths alone).
file(COPY ${WORK}/study/ DESTINATION ${WORK}/study-changed)
file(GLOB p4 ${WORK}/study-changed/s4-*.csv)
foreach(f IN LISTS p4)
  file(READ ${f} text)
  string(REPLACE ",-0." ",-1." text "${text}")
  file(WRITE ${f} "${text}")
endforeach()
execute_process(COMMAND ${DG} calibrate --data ${WORK}/study-changed --participant 4 --gown coarse --generations 2
                        --population 4 --threads 2 --seed 3 --out ${WORK}/r.json
                RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(rc EQUAL 0 OR EXISTS ${WORK}/r.json OR NOT EXISTS ${WORK}/r.json.ckpt
   OR NOT err MATCHES "r\\.json\\.ckpt:2: checkpoint belongs to a different calibration")
  message(FATAL_ERROR "calibrate resumed on changed data (${rc}):\n${out}\n${err}")
endif()
execute_process(COMMAND ${DG} ${again} --out ${WORK}/r.json RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT rc EQUAL 0 OR NOT EXISTS ${WORK}/r.json OR EXISTS ${WORK}/r.json.ckpt
   OR NOT err MATCHES "calibrate: checkpoint [^\n]*/r\\.json\\.ckpt \\(exists: resumed if it is this run's\\)\n"
   OR NOT err MATCHES "\ngeneration 2/2  best L [^\n]*  \\(resumed after generation 1\\)\n"
   OR err MATCHES "generation 1/2")
  message(FATAL_ERROR "calibrate resumed (${rc}):\n${out}\n${err}")
endif()
execute_process(COMMAND ${DG} ${again} --out ${WORK}/w.json RESULT_VARIABLE rc ERROR_VARIABLE err)
file(READ ${WORK}/r.json resumed_file)
file(READ ${WORK}/w.json whole_file)
string(REGEX MATCH "\n  \"objective\": [^,]+," resumed_objective "${resumed_file}")
string(REGEX MATCH "\n  \"objective\": [^,]+," whole_objective "${whole_file}")
if(NOT rc EQUAL 0 OR resumed_objective STREQUAL "" OR NOT resumed_objective STREQUAL whole_objective
   OR err MATCHES "resumed after")
  message(FATAL_ERROR "resumed against uninterrupted calibration: '${resumed_objective}' and '${whole_objective}' (${rc}):\n${err}")
endif()
# predict: participant 4's calibration on the other six participants' 20 trials (coarse gown, ~40 s).
execute_process(COMMAND ${DG} predict --calibration ${WORK}/cal4.json --data ${WORK}/study --out ${WORK}/pred --json
                RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT rc EQUAL 0 OR NOT out MATCHES "\"participant\": \"4\", \"trials\": 20" OR NOT out MATCHES "\"height\": \"middle\""
   OR NOT out MATCHES "\"residual_window_m\": 0.05, \"residual_findings\": \\["
   OR NOT out MATCHES "\\], \"contrast_findings\": \\[[^]]*\\], \"contrast_up_to_m\": 0.3, \"contrast_agrees\": [0-9]+, \"contrast_misses\": [0-9]+, \"contrast_reverses\": [0-9]+}"
   OR NOT EXISTS ${WORK}/pred.csv OR NOT EXISTS ${WORK}/pred.curves.csv OR NOT EXISTS ${WORK}/pred.residual.csv
   OR NOT EXISTS ${WORK}/pred.contrast.csv)
  message(FATAL_ERROR "predict on the study (${rc}):\n${out}\n${err}")
endif()
# predict --discrepancy: the calibration's own error added to every simulated curve. A file
# without sequences has none to measure; c1.json (participant 4's two) on a dataset of his two
# trials and one of participant 5's: the one target scored again, its L not the plain one's.
expect_fail("predict --discrepancy without sequences" "cal4.json: records no calibrated sequence"
            predict --calibration ${WORK}/cal4.json --data ${WORK}/study --discrepancy)
file(MAKE_DIRECTORY ${WORK}/study45)
file(WRITE ${WORK}/study45/manifest.csv "trial_id,participant,height,speed,label,file\n")
foreach(t s4-good-3 s4-miss-2 s5-good-1)
  file(STRINGS ${WORK}/study/manifest.csv row REGEX "^${t},")
  file(APPEND ${WORK}/study45/manifest.csv "${row}\n")
  file(COPY ${WORK}/study/${t}.csv DESTINATION ${WORK}/study45)
endforeach()
foreach(mode plain discrepancy)
  set(flag)
  if(mode STREQUAL "discrepancy")
    set(flag --discrepancy)
  endif()
  execute_process(COMMAND ${DG} predict --calibration ${WORK}/c1.json --data ${WORK}/study45 --threads 2 ${flag} --json
                  RESULT_VARIABLE rc OUTPUT_VARIABLE out_${mode} ERROR_VARIABLE err)
  string(REGEX MATCH "\"objective_median\": [0-9.e+-]+" l_${mode} "${out_${mode}}")
  if(NOT rc EQUAL 0 OR NOT out_${mode} MATCHES "\"trials\": 1," OR l_${mode} STREQUAL "")
    message(FATAL_ERROR "predict ${flag} on participant 5's good trial (${rc}):\n${out_${mode}}\n${err}")
  endif()
endforeach()
if(NOT err MATCHES "corrected by participant '4''s discrepancy" OR l_plain STREQUAL l_discrepancy)
  message(FATAL_ERROR "predict --discrepancy scored the plain simulator (${l_plain}, ${l_discrepancy}):\n${err}")
endif()
# And says so in its summary (the two runs' files were once alike but for L).
if(NOT out_plain MATCHES "\"gown\": \"[a-z]+\", \"discrepancy\": false,"
   OR NOT out_discrepancy MATCHES "\"gown\": \"[a-z]+\", \"discrepancy\": true,")
  message(FATAL_ERROR "predict --json does not record the gown and --discrepancy:\n${out_plain}\n${out_discrepancy}")
endif()
# The residual table: a header and one row per 0.05 m window to the longest measured travel
# (0.85 m: 17 windows) for each of the three heights.
file(STRINGS ${WORK}/pred.residual.csv rows)
list(LENGTH rows n)
if(NOT n EQUAL 52)
  message(FATAL_ERROR "predict: pred.residual.csv has ${n} lines, not a header and 3 x 17 windows")
endif()
# The heights' contrast: a header and one row per window for the middle and the low arm.
file(STRINGS ${WORK}/pred.contrast.csv rows)
list(LENGTH rows n)
if(NOT n EQUAL 35)
  message(FATAL_ERROR "predict: pred.contrast.csv has ${n} lines, not a header and 2 x 17 windows")
endif()
# Both tables as pictures.
foreach(mode residual contrast)
  execute_process(COMMAND /usr/bin/python3 ${PLOT} ${mode} ${WORK}/pred --out ${WORK}/pred-${mode}.png
                  RESULT_VARIABLE rc ERROR_VARIABLE err)
  if(NOT rc EQUAL 0 OR NOT EXISTS ${WORK}/pred-${mode}.png)
    message(FATAL_ERROR "calib_overlay.py ${mode} on predict's tables (${rc}): ${err}")
  endif()
endforeach()
file(STRINGS ${WORK}/pred.csv rows)
list(LENGTH rows n)
if(NOT n EQUAL 21)
  message(FATAL_ERROR "predict: pred.csv has ${n} lines, not a header and 20 trials")
endif()
# A dataset of participant 4 alone has nobody else to predict.
file(MAKE_DIRECTORY ${WORK}/only4)
file(STRINGS ${WORK}/study/manifest.csv manifest)
list(GET manifest 0 header)
set(kept "${header}\n")
foreach(row IN LISTS manifest)
  if(row MATCHES "^[^,]*,4,")
    string(REGEX REPLACE ".*,([^,]*)$" "\\1" file "${row}")
    file(COPY ${WORK}/study/${file} DESTINATION ${WORK}/only4)
    string(APPEND kept "${row}\n")
  endif()
endforeach()
file(WRITE ${WORK}/only4/manifest.csv "${kept}")
expect_fail("predict with nobody else" "other than '4'" predict --calibration ${WORK}/cal4.json --data ${WORK}/only4)
if(HMM)
  execute_process(COMMAND ${DG} build-model --data ${WORK}/study --out ${WORK}/m.dgm --states 5 --json
                  RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT rc EQUAL 0 OR NOT EXISTS ${WORK}/m.dgm OR NOT out MATCHES "\"classes\": 2")
    message(FATAL_ERROR "build-model --data failed (${rc}):\n${out}\n${err}")
  endif()
  # build-model --forces FORCES into FILE: its --json must say JSON_FORCES, and `model show` of the
  # file must match every further argument.
  function(build_and_show forces file json_forces)
    execute_process(COMMAND ${DG} build-model --data ${WORK}/study --out ${file} --states 5 --forces ${forces} --json
                    RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
    execute_process(COMMAND ${DG} model show ${file} RESULT_VARIABLE rc2 OUTPUT_VARIABLE shown ERROR_VARIABLE err2)
    set(ok TRUE)
    if(NOT rc EQUAL 0 OR NOT out MATCHES "\"forces\": \"${json_forces}\"" OR NOT rc2 EQUAL 0)
      set(ok FALSE)
    endif()
    foreach(want IN LISTS ARGN)
      if(NOT shown MATCHES "${want}")
        set(ok FALSE)
      endif()
    endforeach()
    if(NOT ok)
      message(FATAL_ERROR "build-model --forces ${forces} (${rc}, ${rc2}):\n${out}\n${err}\n${shown}\n${err2}")
    endif()
  endfunction()
  # F_motion alone: a model whose second feature is none, shown as such (format 3: training
  # records its sample period and speeds, and version 3 keeps version 2's axis none).
  build_and_show(motion ${WORK}/m1.dgm "motion" "format 3" "feature 1 = none" "sample period: 0.01 s")
  # F_motion and F_lateral: a model whose second feature is the lateral force.
  build_and_show(lateral ${WORK}/ml.dgm "motion,lateral" "feature 1 = \\([+-]f_lateral ")
  # --priors training: each class's share of the training trials (the study: 8 good, 14 missed),
  # where the default gives each 1/2.
  execute_process(COMMAND ${DG} build-model --data ${WORK}/study --out ${WORK}/mp.dgm --states 5 --priors training --json
                  RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  execute_process(COMMAND ${DG} model show ${WORK}/mp.dgm RESULT_VARIABLE rc2 OUTPUT_VARIABLE shown ERROR_VARIABLE err2)
  execute_process(COMMAND ${DG} model show ${WORK}/m.dgm OUTPUT_VARIABLE shown_uniform)
  if(NOT rc EQUAL 0 OR NOT out MATCHES "\"priors\": \"training\"" OR NOT rc2 EQUAL 0
     OR NOT shown MATCHES "class 'good': 5 states, prior 0.3636" OR NOT shown MATCHES "class 'missed': 5 states, prior 0.6364"
     OR NOT shown_uniform MATCHES "class 'good': 5 states, prior 0.5000")
    message(FATAL_ERROR "build-model --priors training (${rc}, ${rc2}):\n${out}\n${err}\n${shown}\n${shown_uniform}")
  endif()
  # --created fixes the bytes: the same data twice give the same file (models/rebuild-default.sh).
  foreach(n 2 3)
    execute_process(COMMAND ${DG} build-model --data ${WORK}/study --out ${WORK}/m${n}.dgm --states 5
                            --created 2026-01-02T03:04:05Z RESULT_VARIABLE rc OUTPUT_QUIET ERROR_VARIABLE err)
    if(NOT rc EQUAL 0)
      message(FATAL_ERROR "build-model --created failed (${rc}): ${err}")
    endif()
  endforeach()
  file(SHA256 ${WORK}/m2.dgm h2)
  file(SHA256 ${WORK}/m3.dgm h3)
  execute_process(COMMAND ${DG} model show ${WORK}/m2.dgm OUTPUT_VARIABLE shown)
  if(NOT h2 STREQUAL h3 OR NOT shown MATCHES "2026-01-02T03:04:05Z")
    message(FATAL_ERROR "build-model --created: ${h2} vs ${h3}\n${shown}")
  endif()
  # --discrepancy: the coarse calibration c1.json's error on participant 4's two sequences,
  # added to its synthesized trials (2 per height, ~15 s). The table has rows for the two heights
  # it was calibrated on; the paper's forces; and the model is not the uncorrected one.
  set(d_opts --calibration ${WORK}/c1.json --synth-dir ${WORK}/d.synth --per-height 2 --seed 3 --threads 2
             --states 3 --created 2026-01-02T03:04:05Z)
  execute_process(COMMAND ${DG} build-model ${d_opts} --discrepancy ${WORK}/study --out ${WORK}/d.dgm --json
                          --training-out ${WORK}/d.train
                  RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(EXISTS ${WORK}/d.dgm.discrepancy.csv)
    file(STRINGS ${WORK}/d.dgm.discrepancy.csv table)
  endif()
  list(GET table 0 header)
  list(FILTER table INCLUDE REGEX "c1.json,(high|low),0.300,")
  list(LENGTH table rows)
  if(NOT rc EQUAL 0 OR NOT out MATCHES "\"forces\": \"motion,vertical\""
     OR NOT header STREQUAL "calibration,height,travel,r_motion,r_lateral,r_vertical" OR NOT rows EQUAL 2)
    message(FATAL_ERROR "build-model --discrepancy (${rc}, ${rows} rows at 0.3 m):\n${out}\n${err}")
  endif()
  execute_process(COMMAND /usr/bin/python3 ${PLOT} discrepancy ${WORK}/d.dgm.discrepancy.csv --out ${WORK}/d.png
                  RESULT_VARIABLE rc ERROR_VARIABLE err)
  if(NOT rc EQUAL 0 OR NOT EXISTS ${WORK}/d.png)
    message(FATAL_ERROR "calib_overlay.py discrepancy on build-model's table (${rc}): ${err}")
  endif()
  execute_process(COMMAND ${DG} build-model ${d_opts} --forces both --out ${WORK}/d0.dgm RESULT_VARIABLE rc OUTPUT_QUIET)
  execute_process(COMMAND ${DG} model show ${WORK}/d.dgm OUTPUT_VARIABLE with)
  execute_process(COMMAND ${DG} model show ${WORK}/d0.dgm OUTPUT_VARIABLE without)
  string(REGEX REPLACE "source:[^\n]*" "" with "${with}")
  string(REGEX REPLACE "source:[^\n]*" "" without "${without}")
  if(NOT rc EQUAL 0 OR with STREQUAL without)
    message(FATAL_ERROR "build-model --discrepancy trained the uncorrected model (${rc}):\n${with}")
  endif()
  # --training-out wrote the corrected trials the HMMs learnt (what classify --weigh-on weighs
  # the model's fellow members on): a model trained on them is the corrected model.
  execute_process(COMMAND ${DG} build-model --data ${WORK}/d.train --states 3 --forces both
                          --created 2026-01-02T03:04:05Z --out ${WORK}/d2.dgm RESULT_VARIABLE rc OUTPUT_QUIET
                  ERROR_VARIABLE err)
  execute_process(COMMAND ${DG} model show ${WORK}/d2.dgm OUTPUT_VARIABLE again)
  string(REGEX REPLACE "source:[^\n]*" "" again "${again}")
  if(NOT rc EQUAL 0 OR NOT again STREQUAL with)
    message(FATAL_ERROR "build-model --training-out: the model of its trials is not the corrected one (${rc}) "
                        "${err}:\n${again}\n---\n${with}")
  endif()
  # A dataset without the calibration's sequences: named, with the missing trial.
  expect_fail("build-model --discrepancy on the wrong data" "holds no trial 's4-good-3'"
              build-model ${d_opts} --discrepancy ${WORK}/d.synth --out ${WORK}/d1.dgm)
endif()
file(REMOVE_RECURSE ${WORK})
