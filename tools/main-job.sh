#!/usr/bin/env bash
# The main job on the bundled default data. Usage: tools/main-job.sh [OUT_DIR]
# Each stage writes into OUT_DIR and prints where; everything runs without ../shared, and uses
# the measured data when it is there.
set -euo pipefail
# OUT as the caller wrote it (relative to where they stand); the default out/ is the repository's.
if [ $# -ge 1 ]; then out=$(realpath -m -- "$1"); else out=""; fi
cd "$(dirname "$0")/.."
out="${out:-out}"
dg=build/release/offline/cli/dressguard
mkdir -p "$out"
# The measured trials, imported afresh: a copy from an earlier run must not stand in for data
# that is gone, and a broken file is an error to show, not "not present".
rm -rf "$out/measured"
if ! import_error=$("$dg" import --out "$out/measured" 2>&1 >/dev/null); then
  if [[ "$import_error" == *"shared/data is not present"* ]]; then
    echo "main-job: shared/data not present, skipping the import of the measured trials"
  else
    echo "main-job: the import of the measured trials failed: $import_error" >&2
    exit 1
  fi
fi

# Simulation (offline/sim): the three outcome trials, one per arm height, on the reduced gown
# (the measured gown when shared/data is present, else the parametric one): force CSVs with a
# JSON summary each, pictures of the scene at start, contact and end, and the force curves.
sim="$out/sim"
mkdir -p "$sim"
for h in high middle low; do
  "$dg" simulate --height "$h" --gown reduced --out "$sim/trial-$h.csv"
  /usr/bin/python3 tools/plot/sim_scene.py "$sim/trial-$h.scene.json" "$sim/scene-$h.png"
  /usr/bin/python3 tools/plot/arm_parts.py "$sim/trial-$h.arm.csv" "$sim/arm-$h.png" --trial "$sim/trial-$h.csv"
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

# Synthesis and training (offline/calib, offline/hmm): a small labelled set from the simulator's
# default parameters (models/default-simulator.json; `dressguard calibrate` makes one for a
# person), the three outcome HMMs, and, where the measured trials are present, their
# classification with the accuracy against travel.
model="$out/model"
mkdir -p "$model"
"$dg" synthesize --calibration models/default-simulator.json --out "$model/synth" \
  --per-height "${MAIN_JOB_PER_HEIGHT:-4}" --gown "${MAIN_JOB_GOWN:-reduced}" --seed 1
# What decided each synthesized label (the 7 cm rule of paper V-A;
# offline/calib/MEASUREMENTS.md, session 31).
/usr/bin/python3 tools/plot/label_evidence.py "$model/label-evidence.png" "default simulator=$model/synth"
"$dg" train --data "$model/synth" --out "$model/stc.dgm"
# Captured, not piped into head or grep -q: under pipefail a reader that stops early kills a
# writer with more to write (SIGPIPE, 141) and fails the pipeline (tests/tools/pipefail_readers.py).
stc_show=$("$dg" model show "$model/stc.dgm")
sed -n 1,8p <<<"$stc_show"
if [ -f "$out/measured/manifest.csv" ]; then
  # The measured trials against the model just trained on the default simulator (none of them
  # in its training: held out).
  echo "main-job: the measured trials classified by $model/stc.dgm"
  "$dg" classify --model "$model/stc.dgm" --data "$out/measured" | tail -5
  # The picture drawn here, as for the in-sample sweep below: a plot that fails ends the job
  # (set -e) with the script's own error, and the job never ends without it.
  "$dg" classify --model "$model/stc.dgm" --data "$out/measured" --sweep 0.05:0.85:0.05 --no-plot \
    --sweep-out "$model/accuracy-vs-travel-stc" >/dev/null
  /usr/bin/python3 tools/plot/hmm_sweep.py "$model/accuracy-vs-travel-stc.csv" "$model/accuracy-vs-travel-stc.png"
  # And against the shipped default model (models/default.dgm: seven people's calibrated
  # simulators, 40 reduced-gown trials per height each). Its calibrations were fitted to most of
  # these trials and its discrepancy term copies their curves into its training, so this figure
  # is in-sample, and its files say so; how many, from the calibrations its source names. The
  # held-out figure (each person left out) is models/README.md's.
  in_sample=$("$dg" model show --json models/default.dgm | /usr/bin/python3 -c '
import csv, json, os, sys
source = json.load(sys.stdin)["source_dataset"].split(" + ")[0]
fitted = set()
for name in source.split(","):
    with open(os.path.join("models", os.path.basename(name) + ".json")) as f:
        fitted |= {s["trial_id"] for s in json.load(f)["sequences"]}
ids = [r["trial_id"] for r in csv.DictReader(open(sys.argv[1]))]
print(f"{sum(i in fitted for i in ids)} of the {len(ids)}")' "$out/measured/manifest.csv")
  echo "main-job: the measured trials classified by models/default.dgm (in-sample: $in_sample trials" \
    "were in its calibrations and discrepancy term)"
  "$dg" classify --model models/default.dgm --data "$out/measured" | tail -5
  "$dg" classify --model models/default.dgm --data "$out/measured" --sweep 0.05:0.85:0.05 --no-plot \
    --sweep-out "$model/accuracy-vs-travel-default-in-sample" >/dev/null
  /usr/bin/python3 tools/plot/hmm_sweep.py "$model/accuracy-vs-travel-default-in-sample.csv" \
    "$model/accuracy-vs-travel-default-in-sample.png" --title "models/default.dgm on the measured trials: IN-SAMPLE
($in_sample were in its calibrations and discrepancy term)"
fi
if [ -f "$out/measured/manifest.csv" ]; then
  # What the simulation gets wrong: the simulator calibrated to participant 4
  # (models/participant4-simulator.json) on the other participants' 20 measured trials (their
  # height, speed and end of travel), scored with the paper's objective beside the median of the
  # same objective between real people of that height, with the vertical force's sign, and the
  # travel windows where it is further from the people's mean than they are from each other.
  "$dg" predict --calibration models/participant4-simulator.json --data "$out/measured" \
    --out "$model/predict-p4" | sed -n '/median L/,$p'
  /usr/bin/python3 tools/plot/calib_overlay.py predict "$model/predict-p4" --out "$model/predict-p4.png"
  /usr/bin/python3 tools/plot/calib_overlay.py residual "$model/predict-p4" --out "$model/residual-p4.png"
fi
# Issue 4's standing: each participant's best shipped calibration on its own sequences (L per
# sequence against the 0.3 goal, the study's repeat floor and the paper's simulator).
/usr/bin/python3 tools/plot/calib_overlay.py standing models/participant*.json --out "$model/calibrations-standing.png"
echo "main-job: synthesized data, model and evaluation in $model"

# Robot side (predictor/): simulated trials as CAN traffic, and what the predictor would do on
# each. The shipped model (models/default.dgm) was trained on seven people's calibrated
# simulators; these trials come from one of them, participant 4's (`simulate --calibration`): the
# high arm (good), the low arm (missed), and the middle arm 8 cm up, below that simulator's
# good/caught edge (11.0 cm above the nominal middle; models/README.md), where the forearm is
# caught. The default-parameter trials above go to the model just trained on the same simulator
# (stc.dgm), when it has a caught class.
robot="$out/robot"
mkdir -p "$robot"
replay() {  # replay MODEL CSV NAME
  "$dg" export-candump --trial "$2" --out "$robot/$3.log" >/dev/null
  printf 'replay of %-44s' "$3:"
  "$dg" replay --model "$1" --log "$robot/$3.log" | sed -n 2p
}
if grep -q "class 'caught'" <<<"$stc_show"; then
  for h in high middle low; do
    replay "$model/stc.dgm" "$sim/trial-$h.csv" "default-parameters-$h ($(sed -n 's/.*"label": "\([a-z]*\)".*/\1/p' "$sim/trial-$h.json"))"
  done
else
  echo "main-job: $model/stc.dgm has no caught class (its few trials held none), so the predictor could not stop on it: no replay"
fi
if [ -f models/default.dgm ]; then
  cal=models/participant4-contrast.json
  for spec in "high 0 high" "low 0 low" "middle 0.08 middle+8cm"; do
    set -- $spec
    "$dg" simulate --calibration "$cal" --height "$1" --arm-offset "$2" --frames 0 --out "$robot/p4-$3.csv" >/dev/null
    replay models/default.dgm "$robot/p4-$3.csv" "participant4-$3 ($(sed -n 's/.*"label": "\([a-z]*\)".*/\1/p' "$robot/p4-$3.json"))"
  done
fi
if [ -f models/default.dgm ] && [ -f "$out/measured/manifest.csv" ]; then
  # The study's 22 real pulls as the bus would carry them, through the predictor with the shipped
  # model: none of them was caught, so every caught stop here is a pull the robot would have
  # ended for nothing (models/README.md, "The stop rule on the real pulls").
  "$dg" export-candump --data "$out/measured" --out "$robot/measured" >/dev/null
  echo "main-job: the stop rule of models/default.dgm on the measured pulls (none was caught)"
  "$dg" replay --model models/default.dgm --logs "$robot/measured" | sed -n '/^outcome/,$p'
  "$dg" replay --model models/default.dgm --logs "$robot/measured" --json > "$robot/measured-stops.json"
  /usr/bin/python3 tools/plot/stop_rule.py "$robot/stop-rule.png" "models/default.dgm=$robot/measured-stops.json"
  # What each stop threshold would cost at the study's mix of pulls (the deployer's choice).
  echo "main-job: pulls stopped for nothing per 100 of the study's protocol, by stop threshold"
  /usr/bin/python3 tools/plot/stop_threshold_curve.py "$robot/stop-threshold-curve.png" --dressguard "$dg" \
    --model models/default.dgm --logs "$robot/measured" --json "$robot/stop-threshold-curve.json"
fi
echo "main-job: candump logs and replays in $robot"
