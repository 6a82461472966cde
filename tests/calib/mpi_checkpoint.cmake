# Two MPI ranks whose checkpoint cannot be written after the first generation (calib_mpi_check
# --checkpoint-fails): both ranks must end, each naming the checkpoint. Rank 0 alone used to
# end, and rank 1 waited for it in the next generation's MPI_Allreduce until killed (a Slurm
# job's whole time limit); the TIMEOUT turns such a hang into a failure.
# -DCHECK=<binary> -DMPIEXEC=<mpiexec> -DWORK=<dir>
file(REMOVE_RECURSE ${WORK})
file(MAKE_DIRECTORY ${WORK})
execute_process(COMMAND ${MPIEXEC} --allow-run-as-root --oversubscribe -n 2 ${CHECK} --checkpoint-fails ${WORK}
                RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err TIMEOUT 60)
if(rc MATCHES "timeout")
  message(FATAL_ERROR "mpirun -n 2 did not end within 60 s: a rank waits for one that stopped (${rc}):\n${out}\n${err}")
endif()
foreach(rank 0 1)
  if(NOT out MATCHES "rank ${rank}: the checkpoint of generation 1 could not be written: [^\n]*ck")
    message(FATAL_ERROR "rank ${rank} did not end with the checkpoint's error (${rc}):\n${out}\n${err}")
  endif()
endforeach()
if(rc EQUAL 0)
  message(FATAL_ERROR "mpirun -n 2 exited 0 after a checkpoint failed:\n${out}\n${err}")
endif()
file(REMOVE_RECURSE ${WORK})
