# `dressguard gown` on bad input exits 2 with one line that names what was wrong, writing nothing.
execute_process(COMMAND ${DG} gown --obj /nonexistent/gown.obj --out /tmp/dg_gown_never_written.obj
                RESULT_VARIABLE rc ERROR_VARIABLE err OUTPUT_QUIET)
if(NOT rc EQUAL 2 OR NOT err MATCHES "/nonexistent/gown.obj")
  message(FATAL_ERROR "missing file: expected exit 2 naming the file, got rc=${rc}: ${err}")
endif()
if(EXISTS /tmp/dg_gown_never_written.obj)
  message(FATAL_ERROR "a failed load wrote its output")
endif()
execute_process(COMMAND ${DG} gown --reduced 7 RESULT_VARIABLE rc ERROR_VARIABLE err OUTPUT_QUIET)
if(NOT rc EQUAL 2 OR NOT err MATCHES "--reduced")
  message(FATAL_ERROR "bad --reduced not named: rc=${rc} ${err}")
endif()
execute_process(COMMAND ${DG} gown --sclae 2 RESULT_VARIABLE rc ERROR_VARIABLE err OUTPUT_QUIET)
if(NOT rc EQUAL 2 OR NOT err MATCHES "--sclae")
  message(FATAL_ERROR "unknown option not named: rc=${rc} ${err}")
endif()
# The parametric gown always works (no shared data needed) and --json is one JSON object.
execute_process(COMMAND ${DG} gown --parametric --json RESULT_VARIABLE rc OUTPUT_VARIABLE out)
if(NOT rc EQUAL 0 OR NOT out MATCHES "^{\"source\": \"parametric\".*\"sleeve_loop\": [0-9]+")
  message(FATAL_ERROR "gown --parametric --json: rc=${rc} ${out}")
endif()
# --out then --in-world --scale 1 reads back the same gown (same stats line for line).
execute_process(COMMAND ${DG} gown --parametric --out ${CMAKE_CURRENT_BINARY_DIR}/dg_gown_roundtrip.obj
                RESULT_VARIABLE rc OUTPUT_QUIET)
execute_process(COMMAND ${DG} gown --parametric --json RESULT_VARIABLE rc1 OUTPUT_VARIABLE a)
execute_process(COMMAND ${DG} gown --obj ${CMAKE_CURRENT_BINARY_DIR}/dg_gown_roundtrip.obj --in-world --scale 1 --json
                RESULT_VARIABLE rc2 OUTPUT_VARIABLE b)
file(REMOVE ${CMAKE_CURRENT_BINARY_DIR}/dg_gown_roundtrip.obj)
string(REGEX REPLACE "\"source\": \"[^\"]*\"|\"seconds\": [0-9.]+" "" a "${a}")
string(REGEX REPLACE "\"source\": \"[^\"]*\"|\"seconds\": [0-9.]+" "" b "${b}")
if(NOT rc EQUAL 0 OR NOT rc2 EQUAL 0 OR NOT a STREQUAL b)
  message(FATAL_ERROR "--out / --in-world round trip differs:\n${a}\n${b}")
endif()
