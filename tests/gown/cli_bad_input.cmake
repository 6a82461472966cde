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
execute_process(COMMAND ${DG} gown --placement sideways RESULT_VARIABLE rc ERROR_VARIABLE err OUTPUT_QUIET)
if(NOT rc EQUAL 2 OR NOT err MATCHES "--placement" OR NOT err MATCHES "sideways")
  message(FATAL_ERROR "bad --placement not named: rc=${rc} ${err}")
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
# --grip-depth beyond the grasp box, and with a placement it does not apply to, are named.
execute_process(COMMAND ${DG} gown --parametric --grip-depth 0.2 RESULT_VARIABLE rc ERROR_VARIABLE err OUTPUT_QUIET)
if(NOT rc EQUAL 2 OR NOT err MATCHES "--grip-depth")
  message(FATAL_ERROR "bad --grip-depth not named: rc=${rc} ${err}")
endif()
execute_process(COMMAND ${DG} gown --placement paper --grip-depth 0.03 RESULT_VARIABLE rc ERROR_VARIABLE err OUTPUT_QUIET)
if(NOT rc EQUAL 2 OR NOT err MATCHES "--grip-depth")
  message(FATAL_ERROR "--grip-depth with --placement paper not refused: rc=${rc} ${err}")
endif()
# A deeper grip holds more vertices (the grasp count in the summary grows).
execute_process(COMMAND ${DG} gown --parametric --json RESULT_VARIABLE rc1 OUTPUT_VARIABLE a)
execute_process(COMMAND ${DG} gown --parametric --grip-depth 0.06 --json RESULT_VARIABLE rc2 OUTPUT_VARIABLE b)
string(REGEX MATCH "\"grasped\": ([0-9]+)" ma "${a}")
set(na ${CMAKE_MATCH_1})
string(REGEX MATCH "\"grasped\": ([0-9]+)" mb "${b}")
set(nb ${CMAKE_MATCH_1})
if(NOT rc1 EQUAL 0 OR NOT rc2 EQUAL 0 OR "${na}" STREQUAL "" OR NOT nb GREATER na)
  message(FATAL_ERROR "--grip-depth 0.06 should grasp more than the default: ${na} -> ${nb}\n${a}\n${b}")
endif()
# --picture replaces the PNG by a rename (tools/plot/figure_file.py), never rewrites the file in
# place: a reader holding the old file (here a hard link to it) keeps it whole.
set(pic ${CMAKE_CURRENT_BINARY_DIR}/dg_gown_picture.png)
file(REMOVE ${pic} ${pic}.old)
file(WRITE ${pic} "the old picture")
file(CREATE_LINK ${pic} ${pic}.old)
execute_process(COMMAND ${DG} gown --parametric --reduced 1500 --picture ${pic} RESULT_VARIABLE rc ERROR_VARIABLE err
                OUTPUT_QUIET)
file(SHA256 ${pic}.old old)
string(SHA256 want "the old picture")
file(READ ${pic} new LIMIT 8 HEX)
file(GLOB leftovers ${CMAKE_CURRENT_BINARY_DIR}/.dg_gown_picture.png.*)
file(REMOVE ${pic} ${pic}.old)
if(NOT rc EQUAL 0 OR NOT old STREQUAL want OR NOT new STREQUAL "89504e470d0a1a0a" OR leftovers)
  message(FATAL_ERROR "gown --picture over an old file: rc=${rc} ${err}; the old file was rewritten (${old}), the "
                      "new one starts ${new}; temporary files left: ${leftovers}")
endif()
# A mesh without a body and a sleeve opening (one triangle: one boundary loop) is bad input that
# names the file, with or without the placement (which looks for the sleeve among the loops).
file(WRITE ${CMAKE_CURRENT_BINARY_DIR}/dg_gown_one_loop.obj "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n")
foreach(how "" "--in-world")
  execute_process(COMMAND ${DG} gown --obj ${CMAKE_CURRENT_BINARY_DIR}/dg_gown_one_loop.obj ${how}
                  RESULT_VARIABLE rc ERROR_VARIABLE err OUTPUT_QUIET)
  if(NOT rc EQUAL 2 OR NOT err MATCHES "dg_gown_one_loop.obj: the mesh has 1 boundary loop")
    message(FATAL_ERROR "gown --obj, one boundary loop ${how}: expected exit 2 naming the file, got rc=${rc}: ${err}")
  endif()
endforeach()
file(REMOVE ${CMAKE_CURRENT_BINARY_DIR}/dg_gown_one_loop.obj)
# gown --json names its source as a JSON string: a '"' or a '\' in the path is escaped.
set(odd "${CMAKE_CURRENT_BINARY_DIR}/dg \"odd\" \\gown.obj")
execute_process(COMMAND ${DG} gown --parametric --reduced 1500 --out "${odd}" RESULT_VARIABLE rc1 OUTPUT_QUIET)
execute_process(COMMAND ${DG} gown --obj "${odd}" --in-world --scale 1 --json RESULT_VARIABLE rc OUTPUT_VARIABLE out
                ERROR_VARIABLE err)
file(REMOVE "${odd}")
string(JSON source ERROR_VARIABLE jerr GET "${out}" source)
if(NOT rc1 EQUAL 0 OR NOT rc EQUAL 0 OR jerr OR NOT source STREQUAL "${odd}")
  message(FATAL_ERROR "gown --obj '${odd}' --json: rc=${rc1},${rc} ${err}; source '${source}' (${jerr})")
endif()
# --scale and --in-world read an OBJ: with --parametric (no file) they are refused, as --obj is.
foreach(opt "--scale;2" "--in-world")
  execute_process(COMMAND ${DG} gown --parametric ${opt} RESULT_VARIABLE rc ERROR_VARIABLE err OUTPUT_QUIET)
  list(GET opt 0 name)
  if(NOT rc EQUAL 2 OR NOT err MATCHES "--parametric and ${name}")
    message(FATAL_ERROR "gown --parametric ${opt}: expected exit 2 naming both, got rc=${rc}: ${err}")
  endif()
endforeach()
# --hang moves the report's and the picture's positions only: --out writes the placed mesh (what
# --in-world reads back as the simulator's start), and the area and mass are the cloth's at rest.
execute_process(COMMAND ${DG} gown --parametric --reduced 1500 --hang --json
                        --out ${CMAKE_CURRENT_BINARY_DIR}/dg_gown_hung.obj RESULT_VARIABLE rc1 OUTPUT_VARIABLE hung)
execute_process(COMMAND ${DG} gown --parametric --reduced 1500 --json RESULT_VARIABLE rc2 OUTPUT_VARIABLE placed)
execute_process(COMMAND ${DG} gown --obj ${CMAKE_CURRENT_BINARY_DIR}/dg_gown_hung.obj --in-world --scale 1 --json
                RESULT_VARIABLE rc3 OUTPUT_VARIABLE back)
file(REMOVE ${CMAKE_CURRENT_BINARY_DIR}/dg_gown_hung.obj)
foreach(key area_m2 mass_kg)
  string(JSON a ERROR_VARIABLE e1 GET "${hung}" ${key})
  string(JSON b ERROR_VARIABLE e2 GET "${placed}" ${key})
  if(e1 OR e2)  # a key missing from both would compare equal as <key>-NOTFOUND
    message(FATAL_ERROR "gown --json lacks ${key}: ${e1} ${e2}\n${hung}\n${placed}")
  endif()
  if(NOT a STREQUAL b)
    message(FATAL_ERROR "gown --hang reports ${key} ${a}, the placed gown ${b}")
  endif()
endforeach()
string(JSON sleeve_back ERROR_VARIABLE e3 GET "${back}" sleeve_center)
string(JSON sleeve_placed ERROR_VARIABLE e4 GET "${placed}" sleeve_center)
if(e3 OR e4)
  message(FATAL_ERROR "gown --json lacks sleeve_center: ${e3} ${e4}\n${back}\n${placed}")
endif()
string(REGEX REPLACE "-(0\\.0*)([],])" "\\1\\2" sleeve_back "${sleeve_back}")  # -0 is 0 (the OBJ's rounding)
string(REGEX REPLACE "-(0\\.0*)([],])" "\\1\\2" sleeve_placed "${sleeve_placed}")
if(NOT rc1 EQUAL 0 OR NOT rc2 EQUAL 0 OR NOT rc3 EQUAL 0 OR NOT sleeve_back STREQUAL sleeve_placed)
  message(FATAL_ERROR "gown --hang --out did not write the placed mesh: sleeve centre ${sleeve_back} read back, "
                      "${sleeve_placed} placed (rc ${rc1} ${rc2} ${rc3})")
endif()
# An output over the --obj it reads is refused before anything is written: --out replaced the
# user's mesh by the placed one, in metres, which the default --scale then scaled a second time
# when read back (4.55 m^2). Also through another spelling of the same path, and for --dump.
set(mine ${CMAKE_CURRENT_BINARY_DIR}/dg_gown_mine.obj)
execute_process(COMMAND ${DG} gown --parametric --reduced 1500 --out ${mine} RESULT_VARIABLE rc OUTPUT_QUIET)
file(SHA256 ${mine} before)
foreach(how "--out;${mine}" "--out;${CMAKE_CURRENT_BINARY_DIR}/./dg_gown_mine.obj" "--dump;${mine}")
  execute_process(COMMAND ${DG} gown --obj ${mine} ${how} RESULT_VARIABLE rc ERROR_VARIABLE err OUTPUT_QUIET)
  file(SHA256 ${mine} after)
  list(GET how 0 opt)
  if(NOT rc EQUAL 2 OR NOT err MATCHES "${opt} .* would write over the input --obj" OR NOT after STREQUAL before)
    message(FATAL_ERROR "gown --obj F ${how}: expected exit 2 naming ${opt} and the input unchanged, got rc=${rc}: "
                        "${err}")
  endif()
endforeach()
file(REMOVE ${mine})
# --out writes the placed gown in metres and says so on its first line: read back without --scale
# it is the same gown (area and mass), not scaled by the measured gown's 1.679 a second time (a
# 4.55 m^2 gown without a word), and a --scale other than 1 is refused naming the file's line 1.
set(placed ${CMAKE_CURRENT_BINARY_DIR}/dg_gown_placed.obj)
execute_process(COMMAND ${DG} gown --parametric --reduced 1500 --json --out ${placed} RESULT_VARIABLE rc1
                OUTPUT_VARIABLE a)
execute_process(COMMAND ${DG} gown --obj ${placed} --json RESULT_VARIABLE rc2 OUTPUT_VARIABLE b ERROR_VARIABLE err2)
execute_process(COMMAND ${DG} gown --obj ${placed} --in-world --json RESULT_VARIABLE rc3 OUTPUT_VARIABLE c
                ERROR_VARIABLE err3)
execute_process(COMMAND ${DG} gown --obj ${placed} --scale 1.679 RESULT_VARIABLE rc4 ERROR_VARIABLE err4 OUTPUT_QUIET)
file(REMOVE ${placed})
foreach(key area_m2 mass_kg)
  string(JSON want ERROR_VARIABLE e1 GET "${a}" ${key})
  string(JSON back ERROR_VARIABLE e2 GET "${b}" ${key})
  string(JSON world ERROR_VARIABLE e3 GET "${c}" ${key})
  if(e1 OR e2 OR e3)
    message(FATAL_ERROR "gown --json lacks ${key}: ${e1} ${e2} ${e3}")
  endif()
  if(NOT rc1 EQUAL 0 OR NOT rc2 EQUAL 0 OR NOT rc3 EQUAL 0 OR NOT want STREQUAL back OR NOT want STREQUAL world)
    message(FATAL_ERROR "gown --out read back without --scale: ${key} ${want} written, ${back} placed again, ${world} "
                        "in W (rc ${rc1} ${rc2} ${rc3}): ${err2} ${err3}")
  endif()
endforeach()
if(NOT rc4 EQUAL 2 OR NOT err4 MATCHES "dg_gown_placed.obj:1: the file says it is in metres.*not 1.679")
  message(FATAL_ERROR "gown --obj OUT --scale 1.679: expected exit 2 naming the file's first line, got rc=${rc4}: "
                      "${err4}")
endif()
