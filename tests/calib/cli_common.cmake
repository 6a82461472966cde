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
