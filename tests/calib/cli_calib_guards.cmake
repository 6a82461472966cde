# What calibrate and the calibration file refuse before anything is simulated (session 84's
# review of the calibration internals): each exits 2 with one line naming the option, or the
# file and line. Each once ran on, or crashed: a checkpoint that could not be written failed
# after a generation (exit 1), a rim_shift box past the parametric gown's rim ended the search in
# its first generation (exit 1), a bounds file's malformed initial value was dropped for the
# box's midpoint, a calibration file's NaN offset or stretch 7 was simulated, and a file of
# 200000 '[' crashed the reader (SIGSEGV). The runs that must fail are bounded (coarse gown,
# 1 x 4), so that without the checks they end within seconds too.
# -DDG=<dressguard> -DWORK=<dir> -DSTUDY=<study dir or empty>
include(${CMAKE_CURRENT_LIST_DIR}/cli_common.cmake)
file(REMOVE_RECURSE ${WORK})
file(MAKE_DIRECTORY ${WORK})

# The calibration file (no study needed).
write_cal4(${WORK}/cal4.json)
file(READ ${WORK}/cal4.json cal4)
string(REPLACE "\"high\": {\"offset_m\": 0.0" "\"high\": {\"offset_m\": nan" text "${cal4}")
file(WRITE ${WORK}/cal_nan.json "${text}")
expect_fail("simulate with a NaN arm offset" "cal_nan.json:3: JSON: unexpected character 'n'"
            simulate --height high --calibration ${WORK}/cal_nan.json --out ${WORK}/sn/t.csv)
string(REPLACE "\"stretch\": 0.2" "\"stretch\": 7" text "${cal4}")
file(WRITE ${WORK}/cal_stretch.json "${text}")
expect_fail("simulate with stretch 7" "cal_stretch.json: cloth.stretch must be within [0, 1]"
            simulate --height high --calibration ${WORK}/cal_stretch.json --out ${WORK}/sb/t.csv)
string(REPLACE "\"friction\": 0.35" "\"friction\": -1" text "${cal4}")
file(WRITE ${WORK}/cal_friction.json "${text}")
expect_fail("simulate with friction -1" "cal_friction.json: cloth.friction cannot be negative"
            simulate --height high --calibration ${WORK}/cal_friction.json --out ${WORK}/sb/t.csv)
string(REPEAT "[" 200000 deep)
file(WRITE ${WORK}/deep.json "${deep}")
expect_fail("simulate with a calibration file nested 200000 deep"
            "deep.json:1: JSON: arrays and objects nested deeper than 256"
            simulate --height high --calibration ${WORK}/deep.json --out ${WORK}/sd/t.csv)
if(EXISTS ${WORK}/sn OR EXISTS ${WORK}/sb OR EXISTS ${WORK}/sd)
  message(FATAL_ERROR "simulate wrote output for a calibration file it refused")
endif()

if(NOT STUDY)
  message("SKIP: shared/data/kapusta2016-calibration-trials not present; the calibrate checks need the study")
  return()
endif()
execute_process(COMMAND ${DG} import --study ${STUDY} --out ${WORK}/study RESULT_VARIABLE rc OUTPUT_QUIET)
set(quick calibrate --data ${WORK}/study --participant 4 --out ${WORK}/c.json --gown coarse --generations 1
          --population 4 --threads 2)
file(WRITE ${WORK}/file "a file, not a folder\n")
expect_fail("calibrate with a checkpoint under a file"
            "--checkpoint ${WORK}/file/c.ckpt: cannot write a checkpoint there"
            ${quick} --checkpoint ${WORK}/file/c.ckpt)
file(WRITE ${WORK}/b.txt "friction 0 2 initial=0.4\n")
expect_fail("calibrate with a bounds file's malformed initial value"
            "b.txt:1: initial value of friction: 'initial=0.4' is not a number" ${quick} --bounds ${WORK}/b.txt)
file(WRITE ${WORK}/b2.txt "friction 0 2\nfriction 0.1 1\n")
expect_fail("calibrate with a parameter given twice in the bounds file" "b2.txt:2: friction was given on line 1 already"
            ${quick} --bounds ${WORK}/b2.txt)
if(EXISTS ${WORK}/c.json)
  message(FATAL_ERROR "calibrate wrote ${WORK}/c.json for a command it refused")
endif()

# A rim_shift held where the jaws hold none of the measured gown (from +0.0431 m: placement.h,
# OpeningGrip) made every candidate unbuildable: the whole budget was spent and the run ended with
# "no candidate could be simulated" (exit 1). Now refused before the search, naming the value and
# the gown, with no checkpoint written.
if(EXISTS ${STUDY}/../gown/fullgown.obj)
  expect_fail("calibrate with the rim held where the jaws hold none of the measured gown"
              "--rim-shift 0.05 holds none of the gown: no candidate could be simulated (rim_shift 0.05 m: "
              ${quick} --rim-shift 0.05 --checkpoint ${WORK}/held.ckpt)
  expect_fail("the same, naming the gown and the grip"
              "fullgown.obj: the gripper's jaws (x -0.21..-0.13, y -0.06..0.06, z 0.055..0.205 m) hold no vertex "
              ${quick} --rim-shift 0.0431 --checkpoint ${WORK}/held.ckpt)
  # The same for a fitted box none of whose rim_shifts holds the gown (session 86 refused only the
  # held value): every candidate was unbuildable and the budget spent (exit 1). Probed at both ends
  # and every 4 cm between (calibration.h, grasp_probes), refused before the search.
  file(WRITE ${WORK}/far.txt "rim_shift 0.045 0.06\n")
  expect_fail("calibrate with a fitted rim_shift box where the jaws hold none of the measured gown"
              "rim_shift's box [0.045, 0.06] m holds none of the gown at any rim_shift (probed at 0.045, 0.06 m: "
              ${quick} --rim-shift fit --bounds ${WORK}/far.txt --checkpoint ${WORK}/held.ckpt)
  if(EXISTS ${WORK}/held.ckpt OR EXISTS ${WORK}/c.json)
    message(FATAL_ERROR "calibrate wrote a checkpoint or a calibration for a rim_shift it refused")
  endif()
endif()

# The parametric gown (no shared/data: the measured gown is absent): its sleeve opening is held
# 1 cm ahead of the jaws, so a rim_shift below -0.01 m cannot be built.
set(ENV{DRESSGUARD_SHARED_DIR} ${WORK}/no-shared)
expect_fail("calibrate with the rim held behind the parametric gown's jaws"
            "--rim-shift -0.02: this gown's sleeve opening is held 0.01 m ahead of the jaws, so a rim_shift below"
            ${quick} --rim-shift -0.02)
file(WRITE ${WORK}/rim.txt "rim_shift -0.03 0.03\n")
expect_fail("calibrate with a bounds file's rim_shift box past the parametric gown's rim"
            "rim.txt:1: rim_shift's box starts at -0.03 m: this gown's sleeve opening is held 0.01 m ahead"
            ${quick} --rim-shift fit --bounds ${WORK}/rim.txt)
# The default box is the measured gown's: clipped, said, recorded, and the search runs.
execute_process(COMMAND ${DG} ${quick} --rim-shift fit --seed 2
                RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT rc EQUAL 0
   OR NOT err MATCHES "calibrate: note: rim_shift's box is \\[-0\\.01, 0\\.04\\] m on this gown, whose sleeve opening")
  message(FATAL_ERROR "calibrate --rim-shift fit on the parametric gown (${rc}):\n${out}\n${err}")
endif()
file(READ ${WORK}/c.json c)  # the searched parameters end with rim_shift, its box the clipped one
if(NOT c MATCHES "\"arm_offset_low\", \"rim_shift\"\\]" OR NOT c MATCHES "\\[-0\\.01[0-9]*, 0\\.04[0-9]*\\]\n +\\]")
  message(FATAL_ERROR "calibrate --rim-shift fit on the parametric gown: the file's parameters or boxes:\n${c}")
endif()
unset(ENV{DRESSGUARD_SHARED_DIR})
file(REMOVE_RECURSE ${WORK})
