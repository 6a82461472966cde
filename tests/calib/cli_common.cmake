# What the calibrate / synthesize / build-model command tests share (cli_calib.cmake and
# cli_calib_study.cmake include it).

# The command exits 2 and its stderr names `expect`.
function(expect_fail what expect)
  execute_process(COMMAND ${DG} ${ARGN} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT rc EQUAL 2)
    message(FATAL_ERROR "${what}: expected exit 2, got ${rc}\n${out}\n${err}")
  endif()
  string(FIND "${err}" "${expect}" at)
  if(at EQUAL -1)
    message(FATAL_ERROR "${what}: stderr lacks '${expect}':\n${err}")
  endif()
endfunction()

# A calibration as `calibrate` writes it: participant 4, the plausibility grid's cloth, on the
# coarse gown.
function(write_cal4 path)
  file(WRITE ${path} "{\"format\": \"dressguard-calibration 1\", \"participant\": \"4\",
 \"cloth\": {\"stretch\": 0.2, \"shear\": 0.5, \"bend\": 0.7, \"friction\": 0.35, \"self_friction\": 0.2, \"arm_compliance\": 0.004},
 \"arm_offsets\": {\"high\": {\"offset_m\": 0.0, \"calibrated\": true}, \"middle\": {\"offset_m\": 0.0, \"calibrated\": false},
                   \"low\": {\"offset_m\": 0.0, \"calibrated\": true}},
 \"objective_kind\": \"area\", \"objective\": 1.0, \"sequences\": [], \"gown\": \"coarse\", \"rig_travel_m\": 0.72}\n")
endfunction()
