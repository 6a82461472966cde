#!/bin/sh
# without_rt_rights.sh PROGRAM [ARGS...]: runs PROGRAM where mlockall and SCHED_FIFO are refused,
# its stderr with its stdout, then says "exit N" (ctest matches what it prints). RLIMIT_RTPRIO
# is 0 and RLIMIT_MEMLOCK $MEMLOCK bytes (0 unless given); as root the capabilities that override
# them (CAP_SYS_NICE, CAP_IPC_LOCK) are also dropped from the bounding and inheritable sets, so
# root's exec of PROGRAM does not get them back. A user without capabilities has neither already.
if [ "$(id -u)" = 0 ]; then
  set -- setpriv --inh-caps=-sys_nice,-ipc_lock --bounding-set=-sys_nice,-ipc_lock "$@"
fi
prlimit --rtprio=0 --memlock="${MEMLOCK:-0}" "$@" 2>&1
echo "exit $?"
