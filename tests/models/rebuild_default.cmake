# models/rebuild-default.sh without its 70 minutes (session 85's tools review, findings 2 and 7),
# run from a copy in WORK/tree, so that nothing here can write over the shipped model:
#  - DATASET mode from another folder, DATASET and DRESSGUARD relative to it (they were read
#    against the repository: "tiny/manifest.csv not found", then "not found" after the -x check),
#    OUT relative too: the model goes to OUT with its .sha256, the tree's default.dgm stays as it
#    was, and the bytes are compared with it (a tiny dataset's model: not the same, exit 1);
#  - again with that model as the tree's default.dgm and the binary from $DRESSGUARD: the same
#    bytes, exit 0;
#  - the committee mode with a stand-in binary from $DRESSGUARD (the second argument forced the
#    DATASET mode) and a relative DRESSGUARD_SHARED_DIR: the caches in build/ are links to
#    folders named after the binary's SHA-256, a cache folder from before is moved aside, the
#    model records the caches' fixed names, and Baum-Welch runs to its tolerance (--max-iter 1000:
#    at the default cap of 100 the shipped model's missed class had stopped short);
#  - more than two arguments print the usage (the comment block, not the code after it).
# -DSRC=<source dir> -DDG=<dressguard> -DWORK=<dir>
file(REMOVE_RECURSE ${WORK})
file(MAKE_DIRECTORY ${WORK}/tree/models ${WORK}/caller/shared/data/gown ${WORK}/stub)
file(COPY ${SRC}/models/rebuild-default.sh ${SRC}/models/default.dgm DESTINATION ${WORK}/tree/models)
file(SHA256 ${WORK}/tree/models/default.dgm shipped)
execute_process(COMMAND /usr/bin/python3 ${SRC}/tools/vm/synthetic_trials.py --out tiny --per-class 2 --seed 1
                WORKING_DIRECTORY ${WORK}/caller RESULT_VARIABLE rc OUTPUT_QUIET ERROR_VARIABLE err)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "synthetic_trials.py failed (${rc}): ${err}")
endif()
file(RELATIVE_PATH dg_here ${WORK}/caller ${DG})
set(script ../tree/models/rebuild-default.sh)
set(fixed STATES=3 CREATED=2026-01-01T00:00:00Z)

execute_process(COMMAND ${CMAKE_COMMAND} -E env OUT=out ${fixed} sh ${script} tiny ${dg_here}
                WORKING_DIRECTORY ${WORK}/caller RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT rc EQUAL 1 OR NOT out MATCHES "wrote ${WORK}/caller/out/default.dgm" OR NOT out MATCHES "not the same bytes as")
  message(FATAL_ERROR "DATASET mode with relative paths from another folder (${rc}): ${out} ${err}")
endif()
file(SHA256 ${WORK}/caller/out/default.dgm made)
file(READ ${WORK}/caller/out/default.dgm.sha256 recorded)
if(NOT recorded STREQUAL "${made}  default.dgm\n")
  message(FATAL_ERROR "OUT's default.dgm.sha256 holds '${recorded}', not ${made}")
endif()
file(SHA256 ${WORK}/tree/models/default.dgm now)
if(NOT now STREQUAL shipped OR EXISTS ${WORK}/caller/out/default.dgm.sha256.tmp)
  message(FATAL_ERROR "the tree's default.dgm changed under OUT, or a temporary was left")
endif()

file(COPY ${WORK}/caller/out/default.dgm DESTINATION ${WORK}/tree/models)
execute_process(COMMAND ${CMAKE_COMMAND} -E env OUT=../again DRESSGUARD=${dg_here} ${fixed} sh ${script} tiny
                WORKING_DIRECTORY ${WORK}/caller RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT rc EQUAL 0 OR NOT out MATCHES "same bytes as ${WORK}/tree/models/default.dgm"
   OR NOT EXISTS ${WORK}/again/default.dgm)
  message(FATAL_ERROR "the same dataset and binary again did not give the same bytes (${rc}): ${out} ${err}")
endif()

# The committee mode: a stand-in that records its calls and writes what it is asked for.
file(WRITE ${WORK}/stub/dressguard [=[#!/bin/sh
echo "$*" >> "$(dirname "$0")/calls.txt"
command=$1
while [ $# -gt 1 ]; do
  if [ "$1" = --out ]; then
    case $command in
      import) echo trial_id > "$2/manifest.csv";;
      build-model) echo stand-in > "$2";;
    esac
  fi
  shift
done
]=])
file(CHMOD ${WORK}/stub/dressguard PERMISSIONS OWNER_READ OWNER_WRITE OWNER_EXECUTE)
file(SHA256 ${WORK}/stub/dressguard key)
string(SUBSTRING ${key} 0 12 key)
file(WRITE ${WORK}/caller/shared/data/gown/fullgown.obj "")
file(WRITE ${WORK}/tree/build/default-model-data/left-by-an-older-binary "")
execute_process(COMMAND ${CMAKE_COMMAND} -E env OUT=committee DRESSGUARD=../stub/dressguard
                        DRESSGUARD_SHARED_DIR=shared sh ${script}
                WORKING_DIRECTORY ${WORK}/caller RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
file(READ ${WORK}/stub/calls.txt calls)
if(NOT rc EQUAL 1 OR NOT calls MATCHES "build-model --calibration models/participant0-contrast.json,"
   OR NOT calls MATCHES "import --study ${WORK}/caller/shared/data/kapusta2016-calibration-trials "
   OR NOT calls MATCHES "--synth-dir build/default-model-data "
   OR NOT calls MATCHES "--discrepancy build/default-model-study "
   OR NOT calls MATCHES "--states 10 --max-iter 1000 "
   OR NOT EXISTS ${WORK}/caller/committee/default.dgm)
  message(FATAL_ERROR "the committee mode with DRESSGUARD and OUT (${rc}): ${out} ${err} calls: ${calls}")
endif()
foreach(cache default-model-data default-model-study)
  file(READ_SYMLINK ${WORK}/tree/build/${cache} target)
  if(NOT target STREQUAL "${cache}.${key}")
    message(FATAL_ERROR "build/${cache} is not a link to ${cache}.${key}: '${target}'")
  endif()
endforeach()
if(NOT EXISTS ${WORK}/tree/build/default-model-study/manifest.csv
   OR NOT EXISTS ${WORK}/tree/build/default-model-data.unkeyed/left-by-an-older-binary
   OR NOT err MATCHES "default-model-data was made by an unknown binary")
  message(FATAL_ERROR "the study was not imported into its keyed folder, or the old cache not moved aside: ${err}")
endif()

execute_process(COMMAND sh ${script} a b c WORKING_DIRECTORY ${WORK}/caller
                RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT rc EQUAL 2 OR NOT err MATCHES "# usage: models/rebuild-default.sh" OR err MATCHES "set -eu")
  message(FATAL_ERROR "the usage text (${rc}): ${err}")
endif()
