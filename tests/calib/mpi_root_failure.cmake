# Two MPI ranks where rank 0 alone cannot write a file (calib_mpi_check MODE): both ranks must
# end, each naming it. MODE --checkpoint-fails: a calibration's checkpoint after the first
# generation; rank 0 alone used to end, and rank 1 waited for it in the next generation's
# MPI_Allreduce until killed (a Slurm job's whole time limit). MODE --synthesis-fails: a
# synthesis's labels.csv, whose failure left rank 1 at the barrier after it. The TIMEOUT turns
# such a hang into a failure.
# -DCHECK=<binary> -DMPIEXEC=<mpiexec> -DWORK=<dir> -DMODE=<--checkpoint-fails|--synthesis-fails>
#   -DEXPECT=<regex that a line of each rank must match after "rank R: ">
file(REMOVE_RECURSE ${WORK})
file(MAKE_DIRECTORY ${WORK})
execute_process(COMMAND ${MPIEXEC} --allow-run-as-root --oversubscribe -n 2 ${CHECK} ${MODE} ${WORK}
                RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err TIMEOUT 60)
if(rc MATCHES "timeout")
  message(FATAL_ERROR "mpirun -n 2 did not end within 60 s: a rank waits for one that stopped (${rc}):\n${out}\n${err}")
endif()
string(REGEX MATCHALL "[^\n]+" lines "${out}")
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
