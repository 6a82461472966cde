#!/bin/sh
# with_robot_emulator.sh EMULATOR SCRIPT: runs SCRIPT (sh, its stderr with its stdout) with a
# fresh dg_modbus_emulator as the robot controller, its port in $PORT and its endpoint in $ROBOT
# (tcp:127.0.0.1:PORT), then says "exit N" with SCRIPT's status and stops the emulator. For the
# bridge's command-line tests that need a robot to answer (ctest matches what they print).
emulator=$1
script=$2
said=$(mktemp)
"$emulator" --port 0 >"$said" &
pid=$!
tries=0
while ! grep -q '^listening on ' "$said" && [ $tries -lt 100 ]; do
  sleep 0.05
  tries=$((tries + 1))
done
PORT=$(sed -n 's/^listening on //p' "$said")
ROBOT="tcp:127.0.0.1:$PORT"
export PORT ROBOT
sh -c "$script" 2>&1
rc=$?
echo "exit $rc"
kill "$pid"
wait "$pid" 2>/dev/null
rm -f "$said"
