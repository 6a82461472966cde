# The calibrate / synthesize / build-model commands: bad input exits 2 with one line naming the
# problem (file and line where there is one); build-model --data trains a model from a dataset.
# The same commands on the study's measured trials: cli_calib_study.cmake.
# -DDG=<dressguard> -DWORK=<dir> -DHMM=<0|1> -DPLOT=<tools/plot/calib_overlay.py>
include(${CMAKE_CURRENT_LIST_DIR}/cli_common.cmake)
file(REMOVE_RECURSE ${WORK})
file(MAKE_DIRECTORY ${WORK})

expect_fail("calibrate without --data" "--data" calibrate --participant 1 --out ${WORK}/c.json)
expect_fail("calibrate with an unknown objective" "--objective" calibrate --data ${WORK} --participant 1 --out ${WORK}/c.json --objective mse)
expect_fail("calibrate with a typo option" "--sed" calibrate --data ${WORK} --participant 1 --out ${WORK}/c.json --sed 3)
expect_fail("calibrate with a bad --sigma0" "--sigma0" calibrate --data ${WORK}/nothing --participant 1 --out ${WORK}/c.json --sigma0 0)
expect_fail("calibrate with a bad --arm-compliance" "--arm-compliance must be fit, fixed or a value (arm_compliance cannot be negative" calibrate --data ${WORK}/nothing --participant 1 --out ${WORK}/c.json --arm-compliance soft)
expect_fail("calibrate from a missing --start" "nostart.json" calibrate --data ${WORK}/nothing --participant 1 --out ${WORK}/c.json --start ${WORK}/nostart.json)
expect_fail("calibrate with a rim behind the jaws" "--rim-shift must be fit, fixed or a value (rim_shift must be within -0.04 and +0.06 m" calibrate --data ${WORK}/nothing --participant 1 --out ${WORK}/c.json --rim-shift -0.05)
expect_fail("calibrate with the fist past the elbow" "--fist-shift must be fit, fixed or a value (fist_shift must be within +-0.2 m" calibrate --data ${WORK}/nothing --participant 1 --out ${WORK}/c.json --fist-shift 0.3)
expect_fail("calibrate with a bad --hem" "--hem" calibrate --data ${WORK}/nothing --participant 1 --out ${WORK}/c.json --hem 0.03)
expect_fail("calibrate with a softening --hem" "--hem" calibrate --data ${WORK}/nothing --participant 1 --out ${WORK}/c.json --hem 0.03,0.5)
expect_fail("calibrate with a negative contrast weight" "--contrast-weight must be in [0, 1000]" calibrate --data ${WORK}/nothing --participant 1 --out ${WORK}/c.json --contrast-weight -1)
expect_fail("calibrate with a negative lateral weight" "--lateral-weight must be in [0, 1000]" calibrate --data ${WORK}/nothing --participant 1 --out ${WORK}/c.json --lateral-weight -1)
expect_fail("calibrate with an unknown way to combine the sequences" "--combine must be sum, worst, bar or count, not 'max'" calibrate --data ${WORK}/nothing --participant 1 --out ${WORK}/c.json --combine max)
expect_fail("calibrate with a negative prune factor" "--prune must be in [0, 100], not '-1'" calibrate --data ${WORK}/nothing --participant 1 --out ${WORK}/c.json --prune -1)
expect_fail("calibrate pruning the position-weighted objective" "--prune needs --objective area" calibrate --data ${WORK}/nothing --participant 1 --out ${WORK}/c.json --prune 1 --objective position-weighted)
expect_fail("calibrate with an unknown friction scheme" "--friction must be improved, constraint or stock, not 'sticky'" calibrate --data ${WORK}/nothing --participant 1 --out ${WORK}/c.json --friction sticky)
expect_fail("calibrate with a support's side but no support" "--support-lateral needs a support" calibrate --data ${WORK}/nothing --participant 1 --out ${WORK}/c.json --support-lateral fit)
expect_fail("calibrate with the support beyond the gown" "--support-depth must be fit, fixed or a value (support_depth must be within 0 (no support) and 1.5 m" calibrate --data ${WORK}/nothing --participant 1 --out ${WORK}/c.json --support-depth 2)
expect_fail("calibrate with the arm beside the opening" "--arm-lateral must be fit, fixed or a value (arm_lateral must be within +-0.1 m" calibrate --data ${WORK}/nothing --participant 1 --out ${WORK}/c.json --arm-lateral 0.15)
expect_fail("calibrate with a weightless gown" "areal_density must be within 0.01 and 1 kg/m" calibrate --data ${WORK}/nothing --participant 1 --out ${WORK}/c.json --density 0)
expect_fail("calibrate on a missing dataset" "manifest.csv" calibrate --data ${WORK}/nothing --participant 1 --out ${WORK}/c.json)
# Words that are no options, counts that would wrap in an int, a switch given a value, an output
# that is a folder: each refused at once (the one-dash "-generations 2" once ran the paper's
# budget, 4294967297 generations ran as 1, a folder --out failed only after the whole search).
expect_fail("calibrate with a one-dash option" "unexpected word '-generations' (options start with --)"
            calibrate --data ${WORK}/nothing --participant 1 --out ${WORK}/c.json -generations 2)
expect_fail("calibrate with a count that wraps" "option --generations: 4294967297 is outside 1-1000000"
            calibrate --data ${WORK}/nothing --participant 1 --out ${WORK}/c.json --generations 4294967297)
expect_fail("calibrate with threads beyond any machine" "option --threads: 99999999999 is outside 0-1024"
            calibrate --data ${WORK}/nothing --participant 1 --out ${WORK}/c.json --threads 99999999999)
expect_fail("a switch given a value" "option --json takes no value"
            calibrate --data ${WORK}/nothing --participant 1 --out ${WORK}/c.json --json=no)
expect_fail("calibrate into a folder" "option --out: '${WORK}' is a folder"
            calibrate --data ${WORK}/nothing --participant 1 --out ${WORK})

# The shipped calibrations' standing on their own sequences as a picture (no study needed: the
# files hold their objectives): per participant the file whose worse sequence is lower, and the
# goal said only where every sequence is within it.
set(M ${CMAKE_CURRENT_LIST_DIR}/../../models)
execute_process(COMMAND /usr/bin/python3 ${PLOT} standing ${M}/participant4-paper-budget.json
                        ${M}/participant4-worst.json ${M}/participant1-worst.json --out ${WORK}/standing.png
                RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT rc EQUAL 0 OR NOT EXISTS ${WORK}/standing.png
   OR NOT out MATCHES "participant 1: participant1-worst\\.json: s1-good-3 0\\.2540, s1-miss-1 0\\.3004\n"
   OR NOT out MATCHES "participant 4: participant4-worst\\.json: s4-good-3 0\\.2337, s4-miss-2 0\\.2341  \\(each <= 0\\.3\\)\n")
  message(FATAL_ERROR "calib_overlay.py standing (${rc}):\n${out}\n${err}")
endif()
file(WRITE ${WORK}/nofits.json "{\"participant\": \"4\"}")
execute_process(COMMAND /usr/bin/python3 ${PLOT} standing ${WORK}/nofits.json --out ${WORK}/none.png
                RESULT_VARIABLE rc ERROR_VARIABLE err)
if(rc EQUAL 0 OR EXISTS ${WORK}/none.png OR NOT err MATCHES "nofits\\.json: no 'sequences'")
  message(FATAL_ERROR "calib_overlay.py standing on a file without sequences (${rc}): ${err}")
endif()

file(WRITE ${WORK}/bad.json "{\"format\": \"dressguard-calibration 1\",\n\"participant\": 4,\n}")
expect_fail("synthesize with a bad calibration file" "bad.json" synthesize --calibration ${WORK}/bad.json --out ${WORK}/s)
expect_fail("synthesize with --per-height 1" "--per-height" synthesize --calibration ${WORK}/bad.json --out ${WORK}/s --per-height 1)
expect_fail("synthesize with a count that wraps" "option --per-height: 4294967298 is outside 2-100000"
            synthesize --calibration ${WORK}/bad.json --out ${WORK}/s --per-height 4294967298)
expect_fail("synthesize on an unknown gown" "--gown must be full, reduced or coarse, not 'bogus'"
            synthesize --calibration ${WORK}/bad.json --out ${WORK}/s --gown bogus)
expect_fail("synthesize with an unknown middle placement" "--middle" synthesize --calibration ${WORK}/bad.json --out ${WORK}/s --middle centre)
expect_fail("synthesize with an unknown high/low placement" "--high-low" synthesize --calibration ${WORK}/bad.json --out ${WORK}/s --high-low wide)
expect_fail("build-model with both inputs" "exactly one" build-model --calibration ${WORK}/bad.json --data ${WORK} --out ${WORK}/m.dgm)
expect_fail("build-model with unknown forces" "--forces" build-model --data ${WORK} --forces torque --out ${WORK}/m.dgm)
expect_fail("build-model with unknown priors" "--priors must be uniform or training"
            build-model --data ${WORK} --priors flat --out ${WORK}/m.dgm)
expect_fail("build-model --discrepancy on a dataset" "--discrepancy needs --calibration"
            build-model --data ${WORK} --discrepancy ${WORK} --out ${WORK}/m.dgm)
expect_fail("predict without --calibration" "--calibration" predict --data ${WORK})
expect_fail("predict with a bad calibration file" "bad.json" predict --calibration ${WORK}/bad.json --data ${WORK})
write_cal4(${WORK}/cal4.json)
expect_fail("predict with a bad --gown" "--gown" predict --calibration ${WORK}/cal4.json --data ${WORK} --gown fine)
expect_fail("predict with a bad --window" "--window" predict --calibration ${WORK}/cal4.json --data ${WORK} --window 0)
# --out PREFIX never writes over its input: the dataset's manifest or a trial file (PREFIX.csv),
# refused before any simulation (`--out DATASET/manifest` once replaced the manifest).
file(MAKE_DIRECTORY ${WORK}/tiny)
file(WRITE ${WORK}/tiny/manifest.csv "trial_id,participant,height,speed,label,file\n"
           "p4,4,high,0.1,good,p4.csv\np5,5,high,0.1,good,p5.csv\n")
foreach(t p4 p5)
  file(WRITE ${WORK}/tiny/${t}.csv "t,travel,f_motion,f_lateral,f_vertical\n0,0,0,0,0\n0.01,0.001,-0.1,0,0.1\n"
             "0.02,0.002,-0.2,0,0.2\n")
endforeach()
file(READ ${WORK}/tiny/manifest.csv manifest_before)
expect_fail("predict --out over its dataset's manifest"
            "--out ${WORK}/tiny/manifest would write ${WORK}/tiny/manifest.csv over the input"
            predict --calibration ${WORK}/cal4.json --data ${WORK}/tiny --out ${WORK}/tiny/manifest)
expect_fail("predict --out over a trial of its dataset" "over the input ${WORK}/tiny/p5.csv"
            predict --calibration ${WORK}/cal4.json --data ${WORK}/tiny --out ${WORK}/tiny/../tiny/p5)
file(READ ${WORK}/tiny/manifest.csv manifest_after)
if(NOT manifest_after STREQUAL manifest_before)
  message(FATAL_ERROR "predict --out wrote over the dataset's manifest:\n${manifest_after}")
endif()

# The pooled STC (paper VII: simulators of several people): build-model with two calibrations
# synthesizes one set per calibration, each the very set `synthesize` makes alone, into a folder
# named after its file, and trains on both in the order given; --data A,B pools datasets alike.
# Coarse gown, 2 trials per height each (~20 s on two cores).
if(HMM)
  file(READ ${WORK}/cal4.json cal4)
  string(REPLACE "\"friction\": 0.35" "\"friction\": 0.6" calB "${cal4}")
  string(REPLACE "\"high\": {\"offset_m\": 0.0" "\"high\": {\"offset_m\": -0.02" calB "${calB}")
  file(WRITE ${WORK}/calB.json "${calB}")
  file(MAKE_DIRECTORY ${WORK}/twin)
  file(WRITE ${WORK}/twin/cal4.json "${cal4}")
  expect_fail("build-model with two calibrations of one name" "two files are named cal4"
              build-model --calibration ${WORK}/cal4.json,${WORK}/twin/cal4.json --out ${WORK}/p.dgm)
  expect_fail("build-model with no calibration in the list" "--calibration names no file"
              build-model --calibration , --out ${WORK}/p.dgm)
  expect_fail("build-model --training-out of two calibrations" "--training-out writes one training set"
              build-model --calibration ${WORK}/cal4.json,${WORK}/calB.json --training-out ${WORK}/t --out ${WORK}/p.dgm)
  set(synth_opts --per-height 2 --seed 3 --threads 2)
  execute_process(COMMAND ${DG} build-model --calibration ${WORK}/cal4.json,${WORK}/calB.json --out ${WORK}/pooled.dgm
                          ${synth_opts} --states 3 --forces motion --created 2026-01-02T03:04:05Z --json
                  RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT rc EQUAL 0 OR NOT out MATCHES "\"training_trials\": 12, \"training_sets\": 2,"
     OR NOT EXISTS ${WORK}/pooled.dgm.synth/cal4/manifest.csv OR NOT EXISTS ${WORK}/pooled.dgm.synth/calB/manifest.csv
     OR NOT err MATCHES "simulator 2 of 2, [^\n]*calB.json -> [^\n]*pooled.dgm.synth/calB\n")
    message(FATAL_ERROR "build-model with two calibrations (${rc}):\n${out}\n${err}")
  endif()
  execute_process(COMMAND ${DG} synthesize --calibration ${WORK}/calB.json --out ${WORK}/sB ${synth_opts}
                  RESULT_VARIABLE rc OUTPUT_QUIET ERROR_VARIABLE err)
  file(READ ${WORK}/sB/manifest.csv alone)
  file(READ ${WORK}/pooled.dgm.synth/calB/manifest.csv pooled)
  file(GLOB trials RELATIVE ${WORK}/sB ${WORK}/sB/sim-*.csv)
  list(LENGTH trials n)
  set(same TRUE)
  foreach(t IN LISTS trials)
    file(SHA256 ${WORK}/sB/${t} a)
    file(SHA256 ${WORK}/pooled.dgm.synth/calB/${t} b)
    if(NOT a STREQUAL b)
      set(same FALSE)
    endif()
  endforeach()
  if(NOT rc EQUAL 0 OR NOT n EQUAL 6 OR NOT same OR NOT alone STREQUAL pooled)
    message(FATAL_ERROR "the pooled build's set of calB is not what synthesize makes alone (${rc}, ${n} trials):\n${err}")
  endif()
  # The same set once more (every trial kept): --json counts the labels per arm height, and each
  # count is the manifest's.
  execute_process(COMMAND ${DG} synthesize --calibration ${WORK}/calB.json --out ${WORK}/sB ${synth_opts} --json
                  RESULT_VARIABLE rc OUTPUT_VARIABLE js ERROR_VARIABLE err)
  if(NOT rc EQUAL 0 OR NOT js MATCHES "\"resumed\": 6,")
    message(FATAL_ERROR "synthesize --json on a finished set (${rc}):\n${js}\n${err}")
  endif()
  if(STUDY)
    # The same set on another gown (--gown overrides the calibration's): refused before anything
    # is simulated; the gown is part of the folder's record (it once kept the coarse gown's trials).
    expect_fail("synthesize resumed on another gown" "holds a synthesis with other settings"
                synthesize --calibration ${WORK}/calB.json --out ${WORK}/sB ${synth_opts} --gown reduced)
  endif()
  file(STRINGS ${WORK}/sB/manifest.csv rows)
  foreach(h high middle low)
    foreach(l good missed caught)
      string(JSON k GET "${js}" per_height ${h} ${l})
      set(m 0)
      foreach(r IN LISTS rows)
        if(r MATCHES "^[^,]*,[^,]*,${h},[^,]*,${l},")
          math(EXPR m "${m} + 1")
        endif()
      endforeach()
      if(NOT k EQUAL m)
        message(FATAL_ERROR "synthesize --json: ${h} ${l} ${k}, the manifest ${m}:\n${js}")
      endif()
    endforeach()
  endforeach()
  # The model from the two sets given as data: the same model, its source naming other folders
  # (the bytes differ there only).
  execute_process(COMMAND ${DG} build-model --data ${WORK}/pooled.dgm.synth/cal4,${WORK}/sB --out ${WORK}/pooled2.dgm
                          --states 3 --forces motion --created 2026-01-02T03:04:05Z
                  RESULT_VARIABLE rc OUTPUT_QUIET ERROR_VARIABLE err)
  execute_process(COMMAND ${DG} model show ${WORK}/pooled2.dgm OUTPUT_VARIABLE shown2)
  execute_process(COMMAND ${DG} model show ${WORK}/pooled.dgm OUTPUT_VARIABLE shown1)
  string(REPLACE "pooled.dgm.synth/calB" "sB" shown1 "${shown1}")
  string(REPLACE "pooled2.dgm" "pooled.dgm" shown2 "${shown2}")
  if(NOT rc EQUAL 0 OR NOT shown1 STREQUAL shown2)
    message(FATAL_ERROR "build-model --data A,B against the pooled build (${rc}):\n${shown1}\n---\n${shown2}\n${err}")
  endif()
  # --label-margin leaves out the trials whose label evidence (labels.csv) sits within the margin
  # of the rule's 7 cm; the rest train the model. Any margin below 7 cm is accepted; a set
  # without labels.csv is named.
  execute_process(COMMAND ${DG} build-model --data ${WORK}/sB --label-margin 0.069 --out ${WORK}/margin.dgm
                          --states 3 --forces motion --json
                  RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  string(REGEX MATCH "\"training_trials\": ([0-9]+)" _ "${out}")
  set(kept "${CMAKE_MATCH_1}")
  string(REGEX MATCH "\"left_out\": ([0-9]+)" _ "${out}")
  set(dropped "${CMAKE_MATCH_1}")
  file(STRINGS ${WORK}/sB/labels.csv stopped REGEX ",(good|caught),")
  list(LENGTH stopped n_stopped)
  if(NOT rc EQUAL 0 OR kept STREQUAL "" OR dropped STREQUAL "")
    message(FATAL_ERROR "build-model --label-margin (${rc}):\n${out}\n${err}")
  endif()
  math(EXPR total "${kept} + ${dropped}")
  if(NOT total EQUAL 6 OR dropped GREATER n_stopped)
    message(FATAL_ERROR "build-model --label-margin: ${kept} kept + ${dropped} left out of 6 trials, ${n_stopped} stopped:\n${out}")
  endif()
  # Exactly the stopped trials whose evidence, max(d_behind, d_ahead), lies within 0.069 m of the
  # rule's 0.07 m, i.e. in (0.001, 0.139) m (synthesis.h, ambiguous_labels); the set must hold
  # stopped trials, or a margin that drops nothing would pass (session 90's test audit).
  set(expected 0)
  foreach(row IN LISTS stopped)
    string(REPLACE "," ";" f "${row}")  # trial_id,height,speed,arm_offset_m,label,travel_m,d_behind_m,d_ahead_m
    list(GET f 6 behind)
    list(GET f 7 ahead)
    set(d ${behind})
    if(ahead GREATER behind)
      set(d ${ahead})
    endif()
    if(d GREATER 0.001 AND d LESS 0.139)
      math(EXPR expected "${expected} + 1")
    endif()
  endforeach()
  if(n_stopped EQUAL 0 OR NOT dropped EQUAL expected)
    message(FATAL_ERROR "build-model --label-margin 0.069 left out ${dropped} trials, labels.csv puts ${expected} of "
                        "its ${n_stopped} stopped ones within the margin:\n${out}")
  endif()
  # The same evidence as a picture (tools/plot/label_evidence.py), and its error for a set without it.
  get_filename_component(plots ${PLOT} DIRECTORY)
  execute_process(COMMAND /usr/bin/python3 ${plots}/label_evidence.py ${WORK}/evidence.png --margin 0.005 sB=${WORK}/sB
                  RESULT_VARIABLE rc ERROR_VARIABLE err)
  if(NOT rc EQUAL 0 OR NOT EXISTS ${WORK}/evidence.png)
    message(FATAL_ERROR "label_evidence.py on a synthesized set (${rc}): ${err}")
  endif()
  execute_process(COMMAND /usr/bin/python3 ${plots}/label_evidence.py ${WORK}/none.png none=${WORK}/missing
                  RESULT_VARIABLE rc ERROR_VARIABLE err)
  if(rc EQUAL 0 OR NOT err MATCHES "missing/labels.csv")
    message(FATAL_ERROR "label_evidence.py on a folder without labels.csv (${rc}): ${err}")
  endif()
  expect_fail("build-model with a label margin of 7 cm" "--label-margin must be in"
              build-model --data ${WORK}/sB --label-margin 0.07 --out ${WORK}/m.dgm)
  file(REMOVE_RECURSE ${WORK}/sB-old)
  file(COPY ${WORK}/sB/ DESTINATION ${WORK}/sB-old)
  file(REMOVE ${WORK}/sB-old/labels.csv)  # a set synthesized before labels.csv existed
  expect_fail("build-model --label-margin on a set without labels.csv" "sB-old/labels.csv: not found"
              build-model --data ${WORK}/pooled.dgm.synth/cal4,${WORK}/sB-old --label-margin 0.01 --out ${WORK}/m.dgm)
  # train pools alike, and names a missing set's manifest.
  execute_process(COMMAND ${DG} train --data ${WORK}/pooled.dgm.synth/cal4,${WORK}/sB --out ${WORK}/t.dgm --states 3 --json
                  RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT rc EQUAL 0 OR NOT out MATCHES "\"trials\": 12,")
    message(FATAL_ERROR "train on two datasets (${rc}):\n${out}\n${err}")
  endif()
  expect_fail("train with a missing second dataset" "nothing/manifest.csv"
              train --data ${WORK}/sB,${WORK}/nothing --out ${WORK}/t2.dgm)
endif()
file(REMOVE_RECURSE ${WORK})
