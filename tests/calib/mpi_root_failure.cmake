# Two MPI ranks where something goes wrong on one or between them (calib_mpi_check MODE): both
# ranks must end, each saying so, where one used to end alone and leave the other waiting in
# its next collective until killed (a Slurm job's whole time limit).
#   --checkpoint-fails: a calibration's checkpoint, written by rank 0 after the first generation;
#   --synthesis-fails: a synthesis's labels.csv, written by rank 0 after every rank's trials;
#   --ranks-disagree: ranks whose CMA-ES states part (as nodes of different CPU kinds could).
# The TIMEOUT turns a hang into a failure.
# -DCHECK=<binary> -DMPIEXEC=<mpiexec> -DWORK=<dir> -DMODE=<one of the above>
#   -DEXPECT=<regex that a line of each rank must match after "rank R: ">
file(REMOVE_RECURSE ${WORK})
file(MAKE_DIRECTORY ${WORK})
execute_process(COMMAND ${MPIEXEC} --allow-run-as-root --oversubscribe -n 2 ${CHECK} ${MODE} ${WORK}
                RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err TIMEOUT 60)
if(rc MATCHES "timeout")
  message(FATAL_ERROR "mpirun -n 2 did not end within 60 s: a rank waits for one that stopped (${rc}):\n${out}\n${err}")
endif()
string(REGEX MATCHALL "[^\n]+" lines "${out}")
# A rank that went on says "unnoticed" (calib_mpi_check, each_rank_ends): never a pass, whatever
# else its line holds.
foreach(line IN LISTS lines)
  if(line MATCHES "unnoticed")
    message(FATAL_ERROR "a rank went on: '${line}' (${rc}):\n${out}\n${err}")
  endif()
endforeach()
foreach(rank 0 1)
  set(said FALSE)
  foreach(line IN LISTS lines)
    if(line MATCHES "^rank ${rank}: ${EXPECT}")
      set(said TRUE)
    endif()
  endforeach()
  if(NOT said)
    message(FATAL_ERROR "rank ${rank} did not end with the error '${EXPECT}' (${rc}):\n${out}\n${err}")
  endif()
endforeach()
if(rc EQUAL 0)
  message(FATAL_ERROR "mpirun -n 2 exited 0 after rank 0 failed:\n${out}\n${err}")
endif()
file(REMOVE_RECURSE ${WORK})
