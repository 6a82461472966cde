#!/usr/bin/env bash
# The main job on the bundled default data. Usage: tools/main-job.sh [OUT_DIR]
# Each stage writes into OUT_DIR and prints where; everything runs without ../shared, and uses
# the measured data when it is there.
set -euo pipefail
cd "$(dirname "$0")/.."
out="${1:-out}"
dg=build/release/offline/cli/dressguard
mkdir -p "$out"
if "$dg" import --out "$out/measured" 2>/dev/null; then
  :
else
  echo "main-job: shared/data not present, skipping the import of the measured trials"
fi

# Simulation (offline/sim): the three outcome trials, one per arm height, on the reduced gown
# (the measured gown when shared/data is present, else the parametric one): force CSVs with a
# JSON summary each, pictures of the scene at start, contact and end, and the force curves.
sim="$out/sim"
mkdir -p "$sim"
for h in high middle low; do
  "$dg" simulate --height "$h" --gown reduced --out "$sim/trial-$h.csv"
  /usr/bin/python3 tools/plot/sim_scene.py "$sim/trial-$h.scene.json" "$sim/scene-$h.png"
done
measured=()
study="${DRESSGUARD_SHARED_DIR:-../shared}/data/kapusta2016-calibration-trials"
if [ -f "$study/good/subject4/3.txt" ]; then
  measured=(--measured "$study/good/subject4/3.txt=measured good (s4)" "$study/miss/subject4/2.txt=measured miss (s4)")
fi
/usr/bin/python3 tools/plot/sim_forces.py "$sim/forces.png" "$sim/trial-high.csv=sim high" \
  "$sim/trial-middle.csv=sim middle" "$sim/trial-low.csv=sim low" "${measured[@]}" \
  --title "simulated trials (default parameters) against travel"
echo "main-job: simulated trials, pictures and force curves in $sim"
