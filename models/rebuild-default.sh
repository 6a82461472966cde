#!/bin/sh
# Rebuilds models/default.dgm, the default model: the simulation-trained classifier of seven
# people's calibrated simulators (the committee of offline/calib/MEASUREMENTS.md, sessions
# 25-30), and records its SHA-256 in models/default.dgm.sha256, which tests/models checks.
#
# What it trains on: each calibration synthesizes 40 trials per arm height (seed 1, both noise
# models, the reduced measured gown); the high and low arms' noise stays inside each simulator's
# repeat band (--high-low repeat-band: only the heights whose noise-free trial stays within one
# measured repeat's distance of the calibrated one); what each simulator gets wrong on its own
# person's measured sequences is added to every trial it synthesized (--discrepancy, Kennedy and
# O'Hagan's discrepancy term); one 10-state HMM per outcome on F_motion and F_lateral; equal
# priors and the predictor's default stop policy (P(caught) > 0.9 for 5 samples).
#
# usage: models/rebuild-default.sh [DATASET [DRESSGUARD]]
#   DATASET     a labelled dataset to train on instead (plain `build-model --data`)
#   DRESSGUARD  the dressguard binary (default: build/release/offline/cli/dressguard)
# Environment: PER_HEIGHT (default 40), STATES (default 10, the paper's), THREADS (default: all
#   cores; the bits do not depend on it), CREATED (creation time to record; the shipped model used
#   CREATED=2026-11-27T04:00:00Z, so the same data give the same bytes), DRESSGUARD_SHARED_DIR
#   (where shared/data is; default ../shared).
# Needs shared/data: the calibrations were made on the measured gown, and the discrepancy term is
# read from the measured trials (imported into build/default-model-study/; neither they nor the
# discrepancy curves, MODEL.dgm.discrepancy.csv, are kept in models/: no licence to redistribute).
# Takes about 70 minutes on two cores (7 x (120 trials + 26 for the repeat bands)), resumable:
# a rerun keeps the trials already in build/default-model-data/.
set -eu
here=$(cd "$(dirname "$0")" && pwd)
top=$(cd "$here/.." && pwd)
if [ $# -gt 2 ]; then
  sed -n '2,27p' "$0" >&2
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
    echo "rebuild-default.sh: $shared/data/gown/fullgown.obj not found: the default model is synthesized on the measured gown and corrected by the measured trials (set DRESSGUARD_SHARED_DIR)" >&2
    exit 2
  }
  study=build/default-model-study
  [ -f "$study/manifest.csv" ] || "$dg" import --study "$shared/data/kapusta2016-calibration-trials" --out "$study" >/dev/null
  committee=""
  for c in participant0-contrast participant1-contrast participant2-simulator participant3-longer \
           participant4-contrast participant5-contrast participant7-simulator; do
    committee="$committee${committee:+,}models/$c.json"
  done
  DRESSGUARD_SHARED_DIR=$shared "$dg" build-model --calibration "$committee" \
    --synth-dir build/default-model-data --per-height "${PER_HEIGHT:-40}" --seed 1 --gown reduced \
    --high-low repeat-band --discrepancy "$study" --forces lateral ${THREADS:+--threads $THREADS} \
    --out "$here/default.dgm" --states "${STATES:-10}" --created "$created"
  rm -f "$here/default.dgm.discrepancy.csv"
fi
(cd "$here" && sha256sum default.dgm > default.dgm.sha256)
"$dg" model show "$here/default.dgm" | head -12
echo "wrote $here/default.dgm and default.dgm.sha256"
