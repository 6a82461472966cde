#!/bin/sh
# Runs inside the test VM (busybox sh, as root, from /init). Every scenario starts the predictor
# daemon on vcan0, replays candump logs with canplayer (or runs the firmware bridge against
# Modbus TCP peers on 127.0.0.1), records the bus with candump -d, stops the daemon with
# SIGTERM, and prints its recording and log between markers on the console (ttyS0) for
# tools/vm/run_vm_tests.py, which decodes the frames and asserts on them.
D=/data
MODEL=$D/model.dgm
say() { echo "DG-VM: [$(cut -d" " -f1 /proc/uptime)] $*"; }
section() { echo "DG-VM-BEGIN $1"; cat "$2"; echo "DG-VM-END $1"; }

if ! ip link add dev vcan0 type vcan 2>/dev/null; then ip2 link add dev vcan0 type vcan || say "FATAL no vcan0"; fi
ip link set vcan0 txqueuelen 1000 2>/dev/null
ip link set up vcan0 || ip2 link set up vcan0
say "vcan0 $(cat /sys/class/net/vcan0/operstate)"

# wait_listening LOG SCENARIO: waits until the daemon's LOG says "listening on": its CAN sockets
# are open from then on, so no frame played after it is lost. A fixed pause is not enough: an
# ASan build under emulation on a busy host took more than the 0.5 s this once waited, and
# missed the first trial's start.
wait_listening() {
  i=0
  while ! grep -q "listening on" "$1" 2>/dev/null; do
    i=$((i + 1))
    if [ $i -gt 600 ]; then say "scenario $2: daemon not listening after 60 s"; return; fi
    sleep 0.1
  done
}

# notify_listen ADDRESS OUT: dg_notify_listen on ADDRESS, its summary into OUT at SIGTERM; returns
# once it listens (a daemon started earlier would find no socket). notify_heard NAME PID: stops
# it and prints the summary with the daemon's PID, for the host to check who said what.
notify_listen() {
  dg_notify_listen "$1" > "$2" 2>&1 &
  npid=$!
  i=0
  while ! grep -q "listening on" "$2" 2>/dev/null && [ $i -lt 100 ]; do i=$((i + 1)); sleep 0.1; done
}
notify_heard() {
  kill -TERM $npid
  wait $npid
  echo "listener_exit $? daemon_pid $2" >> /tmp/$1.notify
  section $1.notify /tmp/$1.notify
}

# scenario NAME "DAEMON ARGS" RECORD_FILTER then the commands to play (as a function "play_NAME").
scenario() {
  name=$1; dargs=$2; filter=$3
  candump -L -d vcan0$filter > /tmp/$name.rec 2>&1 &
  cpid=$!
  # The VM's clock jumps when this shared host deschedules the emulator, so the VM runs use a
  # 200 ms sensor deadline (the deadline logic itself is tested exactly on the host).
  # systemd's notification socket, as a unit with Type=notify and WatchdogSec=0.4 would give it
  # (a ping due every 200 ms): READY=1, WATCHDOG=1 and STOPPING=1 must come from the daemon.
  notify_listen @dg-notify-$name /tmp/$name.notify
  NOTIFY_SOCKET=@dg-notify-$name WATCHDOG_USEC=400000 \
    dressguard-predictor --interface vcan0 --set sensor_timeout_ms=200 $dargs --latency-report > /tmp/$name.log 2>&1 &
  dpid=$!
  sleep 0.5   # candump (started above) is up by then
  wait_listening /tmp/$name.log $name
  say "scenario $name start"
  play_$name
  sleep 0.3
  kill -TERM $dpid
  wait $dpid
  say "scenario $name daemon_exit $?"
  notify_heard $name $dpid
  kill $cpid 2>/dev/null
  wait $cpid 2>/dev/null
  section $name.rec /tmp/$name.rec
  # The serial console is slow under emulation: only the log lines the host checks.
  grep -E "STOP|shutting down|latency|real-time|error|critical" /tmp/$name.log | tail -n 20 > /tmp/$name.short
  section $name.log /tmp/$name.short
}

# Plays a log with canplayer honouring its timestamps (1 ms pacing) compressed by a factor
# (4: one sample every 2.5 ms), to fit the test into minutes; logical time is the counters'.
play_fast() {
  awk -v k=4 '/^\(/ { split(substr($1, 2, length($1) - 2), p, "."); t = p[1] + p[2] / 1e6;
    if (t0 == "") t0 = t; u = (t - t0) / k; printf("(%d.%06d) %s %s\n", int(u), (u - int(u)) * 1e6, $2, $3) }' "$1" > /tmp/fast.log
  play_log /tmp/fast.log "$1"
}

# play_log LOG NAME: canplayer with the log's timestamps; says so when nothing was played, as the
# host counts a trial the daemon never saw as failed, not as "not stopped".
play_log() {
  [ -s "$1" ] || say "PLAYFAIL $2: nothing to play"
  canplayer -I "$1" || say "PLAYFAIL $2: canplayer exit $?"
}

# A: every clean trial and two fault logs; the assertions use the payloads' counters.
play_clean() {
  for f in $D/logs/syn2-*.log $D/logs/fault-isolated-*.log $D/logs/fault-burst-*.log; do
    say "play $(basename $f)"
    play_fast $f
    sleep 1.1   # > 1 s: the robot's trial counters restart with each log (see PROTOCOL.md)
  done
}
# The trial frames (0x180, 0x181) are recorded too: each played trial must appear on the bus.
scenario clean "--model $MODEL" ",080:7FF,300:7FF,180:7FF,181:7FF"

# B: a caught trial past the 10 N limit with the caught rule disabled: the hard limit stops it.
play_hardlimit() { play_fast $D/logs/fault-nocaughtrule-*.log; }
scenario hardlimit "--model $MODEL --set stop_consecutive=100000" ",080:7FF"

# C: the sensor goes silent for 300 ms, played in real time (timestamps honoured); the
# recording keeps the force frames to time the stop against the last one.
play_gap() { head -n 500 $D/logs/fault-gap-*.log > /tmp/gap.log; play_log /tmp/gap.log gap; }
scenario gap "--model $MODEL" ",080:7FF,100:7FF"

# D: a model that does not load: the first trial is refused.
play_nomodel() { head -n 40 $D/logs/syn2-good-0-good.log > /tmp/head.log; play_fast /tmp/head.log; }
scenario nomodel "--model $D/does-not-exist.dgm" ",080:7FF"

# F: stop frames that never reach the bus. tc (iproute2's, as tc2) drops identifier 0x080 on its way out of vcan0, and
# vcan (echo=1) echoes only what it transmits, so the stop socket gets no echo, as from a
# controller that cannot send. The hard limit stops the first trial; its stop is retried,
# unconfirmed. The next trial starts: it is refused (stop_unconfirmed, its own id). Then the way
# out is cleared, and the refusal must reach the bus, and the first trial's stop never.
play_unconfirmed() {
  tc2 qdisc add dev vcan0 root handle 1: prio || say "scenario unconfirmed: tc qdisc failed"
  tc2 filter add dev vcan0 parent 1: basic match "canid(sff 0x080)" action drop || say "scenario unconfirmed: tc filter failed"
  play_fast $D/logs/fault-nocaughtrule-*.log
  sleep 1.1
  head -n 40 $D/logs/syn2-good-0-good.log > /tmp/head.log
  play_fast /tmp/head.log
  sleep 0.1
  tc2 qdisc del dev vcan0 root || say "scenario unconfirmed: tc qdisc del failed"
}
# A 5 s deadline: the second trial's samples end before the way out is cleared, and no timeout
# stop may replace the pending one meanwhile (that would hide a stale stop resent).
scenario unconfirmed "--model $MODEL --set stop_consecutive=100000 --set sensor_timeout_ms=5000" ",080:7FF"

# G: the firmware bridge on SocketCAN, the whole chain: dg_modbus_emulator as the FT 300 (Modbus
# TCP on 127.0.0.1, Fx held at 12.00 N, past the 10 N limit) and as the robot controller; the
# bridge publishes its readings on vcan0, the robot's TrialStart follows (cansend), the predictor
# stops the trial at its first sample (hard limit) with a Stop frame on vcan0, and the bridge
# writes the robot's stop coil. With --predictor-timeout-ms the bridge also watches the
# predictor, which guards the trial: no stop of the bridge's own.
wait_port() {  # wait_port FILE: the port dg_modbus_emulator printed
  i=0
  while ! grep -q "listening on" "$1" 2>/dev/null && [ $i -lt 100 ]; do i=$((i + 1)); sleep 0.1; done
  sed -n 's/^listening on //p' "$1"
}
play_bridge() {
  ip link set lo up || ip2 link set lo up
  dg_modbus_emulator --port 0 --hold 180=1200 > /tmp/sensor.out 2>&1 &
  spid=$!
  dg_modbus_emulator --port 0 > /tmp/robot.out 2>&1 &
  rpid=$!
  sport=$(wait_port /tmp/sensor.out)
  rport=$(wait_port /tmp/robot.out)
  [ -n "$sport" ] && [ -n "$rport" ] || say "scenario bridge: emulator not listening ($sport, $rport)"
  # The scenario's listener is the predictor's (npid): the bridge's is its own. So is its log:
  # /tmp/bridge.log is this scenario's predictor's, and the two, each at its own file offset,
  # overwrote each other's lines (the bridge's exit status among them: a failure under load).
  pred_npid=$npid
  notify_listen @dg-notify-bridge-app /tmp/bridge-app.notify
  NOTIFY_SOCKET=@dg-notify-bridge-app WATCHDOG_USEC=400000 \
    dressguard-bridge --interface vcan0 --sensor tcp:127.0.0.1:$sport --robot tcp:127.0.0.1:$rport \
    --predictor-timeout-ms 300 > /tmp/bridge-app.log 2>&1 &
  bpid=$!
  sleep 1.5   # readings and heartbeats flow
  cansend vcan0 "$(cat $D/bridge-trial-start.txt)" || say "scenario bridge: cansend failed"
  sleep 1.5
  kill -TERM $bpid
  wait $bpid
  echo "bridge_exit $?" >> /tmp/bridge-app.log
  notify_heard bridge-app $bpid
  npid=$pred_npid
  kill $spid $rpid 2>/dev/null
  section bridge-app.log /tmp/bridge-app.log
}
scenario bridge "--model $MODEL" ",080:7FF,100:7FF,180:7FF,700:7FF"

# E: end-to-end latency through the kernel: frame in (the probe's send) to stop frame out (the
# probe's receive), hard-limit trials back to back.
play_latency() {
  bench_predictor --e2e vcan0 --trials 1000 > /tmp/latency.out 2>&1
  echo "bench_exit $?" >> /tmp/latency.out
  section latency.out /tmp/latency.out
}
scenario latency "--model $MODEL" ",7FF:7FF"
