#!/bin/sh
# Rebuilds models/default.dgm, the default model, from the project's own default data: trials
# synthesized by the simulator calibrated to participant 4 (models/participant4-simulator.json,
# the reduced measured gown), 100 trials per arm height (the paper's), seed 1, both noise models,
# the middle arm's noise below the simulator's own good/caught edge (--middle caught-edge: the
# nominal middle never catches on this simulator; offline/calib/README.md, session 10), and
# records its SHA-256 in models/default.dgm.sha256, which tests/models checks.
#
# usage: models/rebuild-default.sh [DATASET [DRESSGUARD]]
#   DATASET     a labelled dataset to train on instead (default: synthesize into
#               build/default-model-data/, resumable: a rerun keeps the trials already there)
#   DRESSGUARD  the dressguard binary (default: build/release/offline/cli/dressguard)
# Environment: PER_HEIGHT (default 100), STATES (default 10, the paper's), CREATED (creation time
#   to record; the shipped model used CREATED=2026-11-24T16:00:00Z, so the same data give the
#   same bytes), DRESSGUARD_SHARED_DIR (where shared/data is; default ../shared).
# Needs the measured gown (shared/data/gown): the calibration was made on it, and the parametric
# gown's sleeve is another simulator. Takes about 20 minutes on two cores (300 trials, then
# training).
set -eu
here=$(cd "$(dirname "$0")" && pwd)
top=$(cd "$here/.." && pwd)
if [ $# -gt 2 ]; then
  sed -n '2,20p' "$0" >&2
  exit 2
fi
dg=${2:-$top/build/release/offline/cli/dressguard}
[ -x "$dg" ] || { echo "rebuild-default.sh: $dg is not built (cmake --build --preset release)" >&2; exit 2; }
cd "$top"
created=${CREATED:-$(date -u +%Y-%m-%dT%H:%M:%SZ)}
if [ $# -ge 1 ]; then
  [ -f "$1/manifest.csv" ] || { echo "rebuild-default.sh: $1/manifest.csv not found" >&2; exit 2; }
  "$dg" build-model --data "$1" --out "$here/default.dgm" --states "${STATES:-10}" --created "$created"
else
  shared=${DRESSGUARD_SHARED_DIR:-$top/../shared}
  [ -f "$shared/data/gown/fullgown.obj" ] || {
    echo "rebuild-default.sh: $shared/data/gown/fullgown.obj not found: the default model is synthesized on the measured gown (set DRESSGUARD_SHARED_DIR)" >&2
    exit 2
  }
  # build-model chooses the forces the calibrated simulator predicts (--forces auto).
  DRESSGUARD_SHARED_DIR=$shared "$dg" build-model --calibration models/participant4-simulator.json \
    --synth-dir build/default-model-data --per-height "${PER_HEIGHT:-100}" --seed 1 --gown reduced \
    --middle caught-edge --out "$here/default.dgm" --states "${STATES:-10}" --created "$created"
fi
(cd "$here" && sha256sum default.dgm > default.dgm.sha256)
"$dg" model show "$here/default.dgm" | head -12
echo "wrote $here/default.dgm and default.dgm.sha256"
