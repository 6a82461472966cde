#!/bin/sh
# signal_while_reading_config.sh PREDICTOR SIGNAL: sends SIGNAL to the predictor daemon while it
# is still reading its config file, then lets it go on; prints its stderr and "exit N" (N is
# 128 + the signal's number when the signal ended it; ctest matches what it prints).
# The config is a FIFO: the daemon's open of it returns only once this script opens it for
# writing, so when that open returns here the daemon is in its start-up, reading the file, and
# stays there until the file's end. It then goes on as without the signal: an empty config, no
# model and interface dg_none, which it fails to open (exit 1).
predictor=$1
signal=$2
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT
mkfifo "$dir/predictor.conf"
"$predictor" --no-rt --interface dg_none --config "$dir/predictor.conf" 2>"$dir/stderr" &
pid=$!
exec 3>"$dir/predictor.conf"
kill -s "$signal" "$pid"
exec 3>&-
wait "$pid"
rc=$?
cat "$dir/stderr"
echo "exit $rc"
