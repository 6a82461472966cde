# dressguard simulate: bad input exits 2 with one line naming what was wrong.
execute_process(COMMAND ${DG} simulate --height sideways --out /tmp/dg_sim_never.csv RESULT_VARIABLE rc ERROR_VARIABLE err OUTPUT_QUIET)
if(NOT rc EQUAL 2 OR NOT err MATCHES "sideways")
  message(FATAL_ERROR "bad height not named: rc=${rc} ${err}")
endif()
execute_process(COMMAND ${DG} simulate --height high --sped 3 --out /tmp/dg_sim_never.csv RESULT_VARIABLE rc ERROR_VARIABLE err OUTPUT_QUIET)
if(NOT rc EQUAL 2 OR NOT err MATCHES "--sped")
  message(FATAL_ERROR "unknown option not named: rc=${rc} ${err}")
endif()
file(WRITE ${TMP}/bad_params.txt "friction 0.3\nstiffness 2\n")
execute_process(COMMAND ${DG} simulate --height high --params ${TMP}/bad_params.txt --out /tmp/dg_sim_never.csv RESULT_VARIABLE rc ERROR_VARIABLE err OUTPUT_QUIET)
if(NOT rc EQUAL 2 OR NOT err MATCHES "bad_params.txt:2")
  message(FATAL_ERROR "bad params file line not named: rc=${rc} ${err}")
endif()
execute_process(COMMAND ${DG} simulate --height high --max-travel 2 --out /tmp/dg_sim_never.csv RESULT_VARIABLE rc ERROR_VARIABLE err OUTPUT_QUIET)
if(NOT rc EQUAL 2 OR NOT err MATCHES "--max-travel")
  message(FATAL_ERROR "bad --max-travel not named: rc=${rc} ${err}")
endif()
execute_process(COMMAND ${DG} simulate --height high --params ${TMP}/bad_params.txt --calibration ${SRC}/models/participant4-simulator.json
                --out /tmp/dg_sim_never.csv RESULT_VARIABLE rc ERROR_VARIABLE err OUTPUT_QUIET)
if(NOT rc EQUAL 2 OR NOT err MATCHES "at most one of --params and --calibration")
  message(FATAL_ERROR "--params with --calibration not refused: rc=${rc} ${err}")
endif()
execute_process(COMMAND ${DG} simulate --height high --friction sticky --out /tmp/dg_sim_never.csv RESULT_VARIABLE rc ERROR_VARIABLE err OUTPUT_QUIET)
if(NOT rc EQUAL 2 OR NOT err MATCHES "--friction must be improved, constraint or stock, not 'sticky'")
  message(FATAL_ERROR "an unknown friction scheme not named: rc=${rc} ${err}")
endif()
if(EXISTS /tmp/dg_sim_never.csv)
  message(FATAL_ERROR "a failed simulate wrote its output")
endif()

# A --max-travel that ends the pull at its first sample (0.05 mm, 0.01 s into the rig's ramp)
# wrote a trial file of one sample, which every reader of a dataset refuses at its line: refused
# before the run, naming it, nothing written; just past it the trial has its two samples.
file(REMOVE ${TMP}/dg_one_sample.csv)
execute_process(COMMAND ${DG} simulate --gown coarse --height high --max-travel 0.00005 --frames 0
                        --out ${TMP}/dg_one_sample.csv RESULT_VARIABLE rc ERROR_VARIABLE err OUTPUT_QUIET)
if(NOT rc EQUAL 2 OR NOT err MATCHES "--max-travel 5e-05 m ends the pull at its first sample, 5e-05 m into"
   OR EXISTS ${TMP}/dg_one_sample.csv)
  message(FATAL_ERROR "--max-travel 0.00005: expected exit 2 naming it and no file, got rc=${rc}: ${err}")
endif()
execute_process(COMMAND ${DG} simulate --gown coarse --height high --max-travel 0.00006 --frames 0
                        --out ${TMP}/two_samples.csv --json RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT rc EQUAL 0 OR NOT out MATCHES "\"samples\": 2,")
  message(FATAL_ERROR "--max-travel 0.00006: expected a trial of 2 samples, got rc=${rc}: ${out} ${err}")
endif()

# --max-travel stops the rig there (a measured trial's own end of travel), and the scene file
# carries the contact forces on the arm at the end (paper eq. 2).
execute_process(COMMAND ${DG} simulate --gown coarse --height low --max-travel 0.05 --frames 0 --out ${TMP}/short.csv --json
                RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT rc EQUAL 0 OR NOT out MATCHES "\"travel\": 0.050000" OR NOT out MATCHES "\"label\": \"missed\"")
  message(FATAL_ERROR "--max-travel 0.05 did not end the trial at 0.05 m: rc=${rc} ${out} ${err}")
endif()
# Without --friction or --calibration the trial runs under the paper's scheme (IV-A.2), the first
# of calib::kFrictionSchemes.
if(NOT out MATCHES "\"friction\": \"improved\"")
  message(FATAL_ERROR "the default friction scheme is not the paper's improved one: ${out}")
endif()
# The summary says what bend means as a fabric: the default bend 0.7 is B of 1-99 mN m, a
# bending length of centimetres to decimetres (offline/sim/model.h, bending_length()).
if(NOT out MATCHES "\"bending_rigidity\": 0\\.0[0-9]" OR NOT out MATCHES "\"bending_length\": 0\\.[0-2]")
  message(FATAL_ERROR "the summary lacks a plausible bending rigidity and length: ${out}")
endif()
# ... and where the sleeve opening hangs at the start of the pull (sim::OpeningShape): some
# centimetres below the jaws, its rim within 50-110 % of its rest length, and its lowest point
# above the low arm's fist centre (0.29 m below the jaws), which passes under it.
if(NOT out MATCHES "\"opening\": {\"depth\": 0\\.[0-2]" OR NOT out MATCHES "\"perimeter_ratio\": (0\\.[5-9]|1\\.0)"
   OR NOT out MATCHES "\"rim_low_above_fist\": 0\\.[0-9]")
  message(FATAL_ERROR "the summary lacks a plausible opening: ${out}")
endif()
file(READ ${TMP}/short.scene.json scene)
if(NOT scene MATCHES "\"contacts\": \\[")
  message(FATAL_ERROR "the scene file has no contacts list")
endif()
# ... and the arm's load per part, one row per sample (0.05 m at the rig's profile: 6 samples).
file(STRINGS ${TMP}/short.arm.csv arm_rows)
list(GET arm_rows 0 arm_header)
list(LENGTH arm_rows arm_n)
if(NOT arm_header STREQUAL "t,travel,elbow_fx,elbow_fy,elbow_fz,fist_fx,fist_fy,fist_fz,forearm_fx,forearm_fy,forearm_fz,upper_arm_fx,upper_arm_fy,upper_arm_fz"
   OR arm_n LESS 3)
  message(FATAL_ERROR "short.arm.csv: header '${arm_header}', ${arm_n} lines")
endif()
# The trial CSV carries its label and conditions on every row after the rig's five columns
# (issue 5: "plus label and metadata"; they were only in FILE.json), and a reader of trial CSVs
# still reads it: export-candump --trial skips the columns after the five.
file(STRINGS ${TMP}/short.csv csv_rows)
list(GET csv_rows 0 csv_header)
list(GET csv_rows 1 csv_first)
list(GET csv_rows -1 csv_last)
if(NOT csv_header STREQUAL "t,travel,f_motion,f_lateral,f_vertical,label,height,speed,arm_offset,seed"
   OR NOT csv_first MATCHES "^0\.01,[-0-9.e]+,[-0-9.e]+,[-0-9.e]+,[-0-9.e]+,missed,low,0\.1,0,0$"
   OR NOT csv_last MATCHES "^[0-9.]+,0\.05,[-0-9.e]+,[-0-9.e]+,[-0-9.e]+,missed,low,0\.1,0,0$")
  message(FATAL_ERROR "short.csv: header '${csv_header}', first row '${csv_first}', last row '${csv_last}'")
endif()
execute_process(COMMAND ${DG} export-candump --trial ${TMP}/short.csv --out ${TMP}/short.log
                RESULT_VARIABLE rc ERROR_VARIABLE err OUTPUT_QUIET)
if(NOT rc EQUAL 0 OR NOT EXISTS ${TMP}/short.log)
  message(FATAL_ERROR "export-candump --trial on simulate's CSV: rc=${rc}: ${err}")
endif()
# A grip the jaws cannot make is named, and nothing is written.
execute_process(COMMAND ${DG} simulate --height high --gown coarse --grip-depth -0.01 --out ${TMP}/dg_grip_never.csv
                RESULT_VARIABLE rc ERROR_VARIABLE err OUTPUT_QUIET)
if(NOT rc EQUAL 2 OR NOT err MATCHES "--grip-depth" OR EXISTS ${TMP}/dg_grip_never.csv)
  message(FATAL_ERROR "bad --grip-depth: expected exit 2 naming it and no file, got rc=${rc}: ${err}")
endif()
# A grip within the options' ranges that leaves the jaws off the gown (the rim 0.1 m ahead of
# them: past the measured sleeve's top, which falls away behind its rim) grasps nothing: `gown`
# refuses it naming the mesh and the grip (it printed "grasped vertices: 0" and exited 0), and
# `simulate` as a usage error naming both options. The parametric gown (without shared/data) has
# a level sleeve top: there the same jaws hold it, and the case checks that they hold cloth.
execute_process(COMMAND ${DG} gown --reduced 1500 --json RESULT_VARIABLE rc_gown OUTPUT_VARIABLE gown_json)
set(parametric OFF)
if(gown_json MATCHES "\"source\": \"parametric\"")
  set(parametric ON)
endif()
# -DEXPECT_GOWN=parametric: the run is meant to be as without shared/data (cli_simulate_without_shared).
if(DEFINED EXPECT_GOWN AND EXPECT_GOWN STREQUAL "parametric" AND NOT parametric)
  message(FATAL_ERROR "expected the parametric gown: rc=${rc_gown} ${gown_json}")
endif()
execute_process(COMMAND ${DG} gown --reduced 1500 --rim-ahead 0.1 --json
                RESULT_VARIABLE rc_gown OUTPUT_VARIABLE gown_json ERROR_VARIABLE gown_err)
execute_process(COMMAND ${DG} simulate --height high --gown coarse --rim-ahead 0.1 --out ${TMP}/dg_grip_off.csv
                RESULT_VARIABLE rc ERROR_VARIABLE err OUTPUT_QUIET)
if(parametric)
  string(REGEX MATCH "\"grasped\": ([0-9]+)" m "${gown_json}")
  set(grasped_far "${CMAKE_MATCH_1}")
  message(STATUS "parametric gown: the jaws 0.1 m behind the rim hold ${grasped_far} vertices of the sleeve's top")
  if(NOT rc_gown EQUAL 0 OR "${grasped_far}" STREQUAL "" OR grasped_far EQUAL 0 OR NOT rc EQUAL 0
     OR NOT EXISTS ${TMP}/dg_grip_off.csv)
    message(FATAL_ERROR "parametric gown, --rim-ahead 0.1: expected the sleeve's top held and a trial, got "
                        "rc=${rc_gown} ${gown_json} ${gown_err}; simulate rc=${rc}: ${err}")
  endif()
  file(REMOVE ${TMP}/dg_grip_off.csv)
else()
  if(NOT rc_gown EQUAL 2 OR NOT gown_err MATCHES "fullgown.obj: the gripper's jaws .* hold no vertex of the gown"
     OR NOT gown_err MATCHES "grip depth 0.015 m and rim_ahead 0.1 m" OR gown_json)
    message(FATAL_ERROR "gown --rim-ahead 0.1: expected exit 2 naming the mesh and the grip, nothing printed, got "
                        "rc=${rc_gown}: ${gown_err} ${gown_json}")
  endif()
  if(NOT rc EQUAL 2 OR NOT err MATCHES "--rim-ahead 0.1" OR NOT err MATCHES "--grip-depth"
     OR NOT err MATCHES "jaws" OR EXISTS ${TMP}/dg_grip_off.csv)
    message(FATAL_ERROR "jaws off the sleeve: expected exit 2 naming the grip options and no file, got "
                        "rc=${rc}: ${err}")
  endif()
endif()
# The rim at or past the fist's back (0.13 m ahead of the jaws: offline/gown/placement.h,
# rim_ahead_limit) would start the hand inside the sleeve: refused on either gown, naming the
# bound. The parametric gown was taken up to 0.5 m, its cloth inside the arm at the start.
foreach(rim 0.13 0.5)
  foreach(cmd "gown;--reduced;1500" "simulate;--height;high;--gown;coarse;--out;${TMP}/dg_grip_past.csv")
    execute_process(COMMAND ${DG} ${cmd} --rim-ahead ${rim} RESULT_VARIABLE rc ERROR_VARIABLE err OUTPUT_QUIET)
    if(NOT rc EQUAL 2 OR NOT err MATCHES "--rim-ahead must be in \\[0, 0.13\\) m: from 0.13 m the opening's rim starts"
       OR EXISTS ${TMP}/dg_grip_past.csv)
      message(FATAL_ERROR "${cmd} --rim-ahead ${rim}: expected exit 2 naming the fist's back, got rc=${rc}: ${err}")
    endif()
  endforeach()
endforeach()

# --calibration: participant 4's cloth and person parameters, and its low arm's offset (+1.105 cm)
# added to --arm-offset.
execute_process(COMMAND ${DG} simulate --gown coarse --height low --arm-offset 0.01 --max-travel 0.05 --frames 0
                        --calibration ${SRC}/models/participant4-simulator.json --out ${TMP}/cal.csv --json
                RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT rc EQUAL 0 OR NOT out MATCHES "\"arm_offset\": 0.02105" OR NOT out MATCHES "\"fist_shift\": 0.0544853"
   OR NOT out MATCHES "\"stretch\": 0.34440")
  message(FATAL_ERROR "--calibration did not reach the simulation: rc=${rc} ${out} ${err}")
endif()
# A calibration's grasp (cloth.rim_shift) moves the rim: 2 cm further ahead of the jaws than the
# gown's own (measured 0.04 m, parametric 0.01 m); --rim-ahead still overrides it.
file(READ ${SRC}/models/participant4-simulator.json p4)
string(REPLACE "\"fist_shift\":" "\"rim_shift\": 0.02, \"fist_shift\":" p4rim "${p4}")
if(p4rim STREQUAL p4)
  message(FATAL_ERROR "participant4-simulator.json has no cloth.fist_shift to place rim_shift beside")
endif()
file(WRITE ${TMP}/p4rim-calibration.json "${p4rim}")
execute_process(COMMAND ${DG} simulate --gown coarse --height high --max-travel 0.01 --frames 0
                        --calibration ${TMP}/p4rim-calibration.json --out ${TMP}/cal_rim.csv --json
                RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT rc EQUAL 0 OR NOT out MATCHES "\"grip\": {\"depth\": 0.0[13]5?, \"rim_ahead\": 0.0[63]}")
  message(FATAL_ERROR "the calibration's rim_shift did not move the rim: rc=${rc} ${out} ${err}")
endif()
execute_process(COMMAND ${DG} simulate --gown coarse --height high --max-travel 0.01 --frames 0 --rim-ahead 0.025
                        --calibration ${TMP}/p4rim-calibration.json --out ${TMP}/cal_rim2.csv --json
                RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT rc EQUAL 0 OR NOT out MATCHES "\"rim_ahead\": 0.025}")
  message(FATAL_ERROR "--rim-ahead did not override the calibration's grasp: rc=${rc} ${out} ${err}")
endif()

# A short coarse-gown simulate with `option value` that must exit 2 saying `expect` and write no
# file (--speed, --seed and the like: refused before anything is simulated).
function(expect_simulate_refused option value expect)
  set(out ${TMP}/dg_refused_never.csv)
  file(REMOVE ${out})
  execute_process(COMMAND ${DG} simulate --gown coarse --height high --max-travel 0.01 --frames 0 ${option} ${value}
                          --out ${out} RESULT_VARIABLE rc ERROR_VARIABLE err OUTPUT_QUIET)
  if(NOT rc EQUAL 2 OR NOT err MATCHES "${expect}" OR EXISTS ${out})
    message(FATAL_ERROR "${option} ${value}: expected exit 2 saying '${expect}' and no file, got rc=${rc}: ${err}")
  endif()
endfunction()

# --speed within sim::kMinPullSpeed-kMaxPullSpeed (0.05-0.3 m/s, around the study's 0.1 and 0.15):
# the pull's time limit grows as 1 / speed, and 1e-6 m/s ran for days.
foreach(speed 0.5 1e-6 0.04)
  expect_simulate_refused(--speed ${speed} "--speed must be within 0.05 and 0.3 m/s")
endforeach()

# --frames: each time once, at most 100 of them, from where settling can start (its cap, 10 s
# before the pull) to the pull's time limit (here 0.01 m / 0.1 m/s + 5.1 s); out of range, a time
# was undefined behaviour (-1e300) or kept no frame, and 500 copies of 0 kept 500 frames.
file(REMOVE ${TMP}/dg_frames_never.csv)
set(many_frames 0)
foreach(i RANGE 1 100)
  string(APPEND many_frames ",0.${i}")
endforeach()
foreach(frames "0,0.5,0" "-10.5" "5.3" "${many_frames}" "-1e300,-1")
  execute_process(COMMAND ${DG} simulate --gown coarse --height high --max-travel 0.01 --frames=${frames}
                  --out ${TMP}/dg_frames_never.csv RESULT_VARIABLE rc ERROR_VARIABLE err OUTPUT_QUIET)
  if(NOT rc EQUAL 2 OR NOT err MATCHES "--frames" OR EXISTS ${TMP}/dg_frames_never.csv)
    message(FATAL_ERROR "--frames=${frames}: expected exit 2 naming it and no file, got rc=${rc}: ${err}")
  endif()
endforeach()
# The bounds themselves are times (the pull ends long before its limit: the end frame is kept).
execute_process(COMMAND ${DG} simulate --gown coarse --height high --max-travel 0.01 --frames=-1,0,5.2
                --out ${TMP}/dg_frames.csv RESULT_VARIABLE rc ERROR_VARIABLE err OUTPUT_QUIET)
file(READ ${TMP}/dg_frames.scene.json scene)
string(REGEX MATCHALL "{\"t\": [-0-9.e]+" frame_ts "${scene}")
if(NOT rc EQUAL 0 OR NOT frame_ts MATCHES "^{\"t\": -1;{\"t\": 0;")
  message(FATAL_ERROR "--frames=-1,0,5.2 (the pull's time limit) kept ${frame_ts}: rc=${rc} ${err}")
endif()

# --out naming a folder is refused before the simulation (it failed only after the whole run).
execute_process(COMMAND ${DG} simulate --gown coarse --height high --max-travel 0.01 --frames 0 --out ${TMP}
                RESULT_VARIABLE rc ERROR_VARIABLE err OUTPUT_QUIET)
if(NOT rc EQUAL 2 OR NOT err MATCHES "--out: '.*' is a folder")
  message(FATAL_ERROR "--out FOLDER: expected exit 2 naming --out, got rc=${rc}: ${err}")
endif()

# --out may not be one of the files simulate writes beside it (X.json was written as the CSV and
# then replaced by the summary).
file(REMOVE ${TMP}/dg_side.json ${TMP}/dg_side.scene.json)
foreach(name dg_side.json dg_side.scene.json)
  execute_process(COMMAND ${DG} simulate --gown coarse --height high --max-travel 0.01 --frames 0 --out ${TMP}/${name}
                  RESULT_VARIABLE rc ERROR_VARIABLE err OUTPUT_QUIET)
  if(NOT rc EQUAL 2 OR NOT err MATCHES "--out" OR EXISTS ${TMP}/${name})
    message(FATAL_ERROR "--out ${name}: expected exit 2 naming --out and no file, got rc=${rc}: ${err}")
  endif()
endforeach()

# The CSV is written last: a run that fails writing a side file (here a folder in the way of
# FILE.arm.csv) leaves no new CSV beside old side files.
file(REMOVE ${TMP}/dg_commit.csv)
file(MAKE_DIRECTORY ${TMP}/dg_commit.arm.csv)
execute_process(COMMAND ${DG} simulate --gown coarse --height high --max-travel 0.01 --frames 0 --out ${TMP}/dg_commit.csv
                RESULT_VARIABLE rc ERROR_VARIABLE err OUTPUT_QUIET)
file(REMOVE_RECURSE ${TMP}/dg_commit.arm.csv)
if(rc EQUAL 0 OR EXISTS ${TMP}/dg_commit.csv)
  message(FATAL_ERROR "a side file that could not be written: expected a failure and no CSV, got rc=${rc}: ${err}")
endif()

# The summary is JSON whatever the path: a '"' and a '\' are escaped, and a path longer than the
# 2048 characters it was once cut to stays whole (the cut summary was invalid JSON, exit 0).
string(REPEAT "d" 200 long)
string(REPEAT "/${long}" 10 deep)
foreach(dir "${TMP}/dg \"quoted\" \\dir" "${TMP}${deep}")
  file(MAKE_DIRECTORY "${dir}")
  execute_process(COMMAND ${DG} simulate --gown coarse --height high --max-travel 0.01 --frames 0 --out "${dir}/t.csv"
                          --json RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  file(READ "${dir}/t.json" summary)
  string(JSON printed ERROR_VARIABLE jerr GET "${out}" out)
  string(JSON written ERROR_VARIABLE jerr2 GET "${summary}" out)
  if(NOT rc EQUAL 0 OR jerr OR jerr2 OR NOT printed STREQUAL "${dir}/t.csv" OR NOT written STREQUAL printed)
    message(FATAL_ERROR "summary of --out '${dir}/t.csv': rc=${rc} ${err}; printed '${printed}' (${jerr}), "
                        "written '${written}' (${jerr2})")
  endif()
endforeach()
file(REMOVE_RECURSE "${TMP}/dg \"quoted\" \\dir" "${TMP}/${long}")

# --arm-offset's +-0.5 m holds for the offset simulated, a calibration's included: it was checked
# before the calibration's was added (participant 4's low arm: +0.011 m), and 0.495 m ran at
# 0.506 m. Refused naming both parts and the sum, nothing written.
file(REMOVE ${TMP}/dg_offset_never.csv)
execute_process(COMMAND ${DG} simulate --gown coarse --height low --arm-offset 0.495 --max-travel 0.01 --frames 0
                        --calibration ${SRC}/models/participant4-simulator.json --out ${TMP}/dg_offset_never.csv
                RESULT_VARIABLE rc ERROR_VARIABLE err OUTPUT_QUIET)
string(CONCAT expect "--arm-offset 0.495 plus the calibration's 0.0110519 m for the low arm is 0.506052 m; "
                     "the sum must be within \\+-0.5 m")
if(NOT rc EQUAL 2 OR NOT err MATCHES "${expect}" OR EXISTS ${TMP}/dg_offset_never.csv)
  message(FATAL_ERROR "--arm-offset 0.495 with a calibration's +0.011: expected exit 2 naming the sum, "
                      "got rc=${rc}: ${err}")
endif()

# --seed is the noise models' uint64_t: its upper half was refused as "not an integer" (read as a
# long). 2^64 - 1 runs and is reported whole; a negative one, or one past 2^64 - 1, is named so.
execute_process(COMMAND ${DG} simulate --gown coarse --height high --max-travel 0.01 --frames 0 --noise
                        --seed 18446744073709551615 --out ${TMP}/dg_seed.csv --json
                RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT rc EQUAL 0 OR NOT out MATCHES "\"seed\": 18446744073709551615,")
  message(FATAL_ERROR "--seed 18446744073709551615: expected a run with that seed, got rc=${rc}: ${out} ${err}")
endif()
foreach(case "-1|--seed: must not be negative, not -1" "18446744073709551616|--seed: 18446744073709551616 is beyond"
             "1e3|--seed: not an integer: '1e3'")
  string(REPLACE "|" ";" case "${case}")
  list(GET case 0 seed)
  list(GET case 1 expect)
  expect_simulate_refused(--seed ${seed} "${expect}")
endforeach()
