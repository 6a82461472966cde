#!/bin/sh
# Rebuilds models/default.dgm, the default model, from the project's own default data: trials
# synthesized by the simulator with models/default-simulator.json (the simulator's default
# parameters, reduced gown, 20 trials per arm height, seed 1), and records its SHA-256 in
# models/default.dgm.sha256, which tests/models checks.
#
# usage: models/rebuild-default.sh [DATASET [DRESSGUARD]]
#   DATASET     a labelled dataset to train on instead (default: synthesize into
#               build/default-model-data/, resumable: a rerun keeps the trials already there)
#   DRESSGUARD  the dressguard binary (default: build/release/offline/cli/dressguard)
# Environment: STATES (default 10, the paper's), CREATED (creation time to record; the shipped
#   model used CREATED=2026-11-22T05:00:00Z, so the same data give the same bytes).
# Takes about 6 minutes on two cores (60 simulated trials, then training).
set -eu
here=$(cd "$(dirname "$0")" && pwd)
top=$(cd "$here/.." && pwd)
if [ $# -gt 2 ]; then
  sed -n '2,14p' "$0" >&2
  exit 2
fi
dg=${2:-$top/build/release/offline/cli/dressguard}
[ -x "$dg" ] || { echo "rebuild-default.sh: $dg is not built (cmake --build --preset release)" >&2; exit 2; }
cd "$top"
if [ $# -ge 1 ]; then
  data=$1
else
  data=build/default-model-data
  "$dg" synthesize --calibration models/default-simulator.json --out "$data" --per-height 20 --seed 1 --gown reduced
fi
[ -f "$data/manifest.csv" ] || { echo "rebuild-default.sh: $data/manifest.csv not found" >&2; exit 2; }
created=${CREATED:-$(date -u +%Y-%m-%dT%H:%M:%SZ)}
"$dg" train --data "$data" --out "$here/default.dgm" --states "${STATES:-10}" --created "$created"
(cd "$here" && sha256sum default.dgm > default.dgm.sha256)
"$dg" model show "$here/default.dgm" | head -12
echo "wrote $here/default.dgm and default.dgm.sha256"
