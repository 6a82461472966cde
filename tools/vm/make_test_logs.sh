#!/usr/bin/env bash
# Regenerates the robot-side test logs under tests/data/robot/ (committed) from synthetic trials
# (tools/vm/synthetic_trials.py, seed 2: not the seed-1 trials the test model is fitted on).
#   tools/vm/make_test_logs.sh build/release/offline/cli/dressguard [tests/data/robot]
# File names carry the expected outcome: <trial>-<label>.log is a clean trial whose outcome is
# its label (caught: stopped for "caught" before the rig's 10 N limit; good, missed: no stop);
# fault-*-expect-<reason>.log must stop for <reason>; fault-*-nostop.log must not stop.
set -euo pipefail
DG=${1:?usage: make_test_logs.sh DRESSGUARD_BIN [OUTDIR]}
OUT=${2:-$(dirname "$0")/../../tests/data/robot}
HERE=$(cd "$(dirname "$0")" && pwd)
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
/usr/bin/python3 "$HERE/synthetic_trials.py" --out "$tmp/syn" --per-class 3 --seed 2 >/dev/null
# Only the logs are replaced: the folder's README stays, and a folder holding anything else is
# not a test-log folder (refused rather than cleared).
mkdir -p "$OUT"
for f in "$OUT"/* "$OUT"/.[!.]*; do
  [ -e "$f" ] || continue
  case "$(basename "$f")" in *.log|README.md) ;; *) echo "make_test_logs.sh: $OUT holds $f: not a test-log folder" >&2; exit 2;; esac
done
rm -f "$OUT"/*.log
"$DG" export-candump --data "$tmp/syn" --out "$OUT" --trial-id 1 >/dev/null
g0="$tmp/syn/syn2-good-0.csv"
c0="$tmp/syn/syn2-caught-0.csv"
# Isolated faults on a good trial: counted, discarded or tolerated, never a stop.
"$DG" export-candump --trial "$g0" --speed 0.1 --height high --trial-id 101 --counter-start 200 \
  --corrupt 50,300 --drop 120 --repeat 200 --delay 250:2 --out "$OUT/fault-isolated-good-nostop.log" >/dev/null
# The sensor falls silent for 300 ms (deadline 50 ms): fail-safe stop.
"$DG" export-candump --trial "$g0" --speed 0.1 --height high --trial-id 102 --gap 150:300 \
  --out "$OUT/fault-gap-good-expect-sensor_timeout.log" >/dev/null
# A burst of 8 corrupted frames: over the bad-frame budget.
"$DG" export-candump --trial "$g0" --speed 0.1 --height high --trial-id 103 --corrupt 100,101,102,103,104,105,106,107 \
  --out "$OUT/fault-burst-good-expect-bad_frames.log" >/dev/null
# A caught trial sent past the rig's limit, replayed with the caught rule disabled
# (stop_consecutive = 100000): the hard limit must stop it at the first sample above 10 N.
"$DG" export-candump --trial "$c0" --speed 0.1 --height middle --trial-id 104 --rig-limit 0 \
  --out "$OUT/fault-nocaughtrule-caught-expect-hard_limit.log" >/dev/null
ls "$OUT" | grep -c '\.log$' | xargs echo "test logs written to $OUT:"
