#!/bin/sh
# Rebuilds models/default.dgm from a labelled dataset (the simulator's synthesized data in the
# release) and records its SHA-256 in models/default.dgm.sha256, which tests/models checks.
#
# usage: models/rebuild-default.sh DATASET [DRESSGUARD]
#   DATASET     a dataset folder (manifest.csv + trial CSVs) with good/missed/caught labels
#   DRESSGUARD  the dressguard binary (default: build/release/offline/cli/dressguard)
# Environment: STATES (default 10, the paper's), CREATED (creation time to record, default now;
#   set it, e.g. CREATED=2026-01-01T00:00:00Z, for byte-identical rebuilds of the same data).
set -eu
here=$(cd "$(dirname "$0")" && pwd)
if [ $# -lt 1 ] || [ $# -gt 2 ]; then
  sed -n '2,10p' "$0" >&2
  exit 2
fi
data=$1
dg=${2:-$here/../build/release/offline/cli/dressguard}
[ -x "$dg" ] || { echo "rebuild-default.sh: $dg is not built (cmake --build --preset release)" >&2; exit 2; }
[ -f "$data/manifest.csv" ] || { echo "rebuild-default.sh: $data/manifest.csv not found" >&2; exit 2; }
created=${CREATED:-$(date -u +%Y-%m-%dT%H:%M:%SZ)}
"$dg" train --data "$data" --out "$here/default.dgm" --states "${STATES:-10}" --created "$created"
(cd "$here" && sha256sum default.dgm > default.dgm.sha256)
"$dg" model show "$here/default.dgm" | head -12
echo "wrote $here/default.dgm and default.dgm.sha256"
