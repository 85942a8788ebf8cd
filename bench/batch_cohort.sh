#!/usr/bin/env bash
# `endocast batch` over a cohort (issue 37's acceptance): every shared scan with its preset, the
# colon phantoms, one corrupt file and one scan without the structure asked for; run with 1 and
# with 2 workers (studies per hour and the speed-up), then again to time the resume (every
# finished study skipped).
# Usage (repository root, ../shared beside it): bench/batch_cohort.sh [OUT]
set -euo pipefail
out=${1:-bench/out/cohort}
data=$(cd ../shared/data && pwd)
source "$(dirname "$0")/cargo_bin.sh"
endocast_binary
mkdir -p "$out/scans"
for p in colon colon-prone; do
  [ -f "$out/scans/$p.nii.gz" ] || $endocast phantom "$p" --size 128 -o "$out/scans/$p.nii.gz" >/dev/null
done
[ -f "$out/scans/polyps.nii.gz" ] ||
  $endocast phantom colon --size 128 --polyps 6 --seed 3 -o "$out/scans/polyps.nii.gz" >/dev/null
size=$(stat -c %s "$out/scans/colon.nii.gz")
head -c $((size / 2)) "$out/scans/colon.nii.gz" >"$out/scans/corrupt.nii.gz"
cat >"$out/manifest.csv" <<CSV
scan,preset,output,orientation
$data/abdomen-ct-pancreas-dicom,colonoscopy,abdomen-colon,
$data/abdomen-ct-pancreas-dicom,angioscopy,abdomen-aorta,
$data/chest-ct-airways-dicom,bronchoscopy,chest-airways,
$data/head-ct-stanford-cthead/CThead.nhdr,sinus,cthead-sinus,LPI
$data/head-ct-ge-gantry-tilt/GE,sinus,ge-head-sinus,
$data/brain-mri-t1/chris_t1.nii.gz,ventricles,t1-ventricles,
$data/brain-mri-flair-nrrd/FLAIR.nrrd,ventricles,flair-ventricles,
$data/aorta-stent-cta/stent.nrrd,angioscopy,stent-aorta,
$data/classic-engine-ct/engine.nii.gz,colonoscopy,engine-no-colon,
scans/colon.nii.gz,colonoscopy,colon,
scans/colon-prone.nii.gz,colonoscopy,colon-prone,
scans/polyps.nii.gz,colonoscopy,polyps,
scans/corrupt.nii.gz,colonoscopy,corrupt,
CSV
echo "$(nproc) cores, $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | xargs), $(date -u +%F), load $(cut -d' ' -f1-3 /proc/loadavg)"
for workers in 1 2; do
  rm -rf "$out/run$workers"
  start=$(date +%s.%N)
  $endocast batch "$out/manifest.csv" -o "$out/run$workers" --workers "$workers" 2>"$out/run$workers.log"
  took=$(echo "$(date +%s.%N) - $start" | bc)
  echo "workers $workers: $took s for 13 studies"
done
start=$(date +%s.%N)
$endocast batch "$out/manifest.csv" -o "$out/run2" --workers 2 2>/dev/null | head -1
echo "resume: $(echo "$(date +%s.%N) - $start" | bc) s"
# Per pipeline (preset) with one worker: seconds per study, and studies an hour at that rate.
python3 - "$out" <<'PY'
import csv, json, sys
out = sys.argv[1]
preset = {row["output"]: row["preset"] for row in csv.DictReader(open(f"{out}/manifest.csv"))}
per = {}
for r in json.load(open(f"{out}/run1/summary.json"))["studies"]:
    name = r["output"].rstrip("/").split("/")[-1]
    if r["status"] == "ok":
        per.setdefault(preset[name], []).append(r["seconds"])
for p, s in sorted(per.items()):
    print(f"{p}: {len(s)} studies, {sum(s):.0f} s, {3600 * len(s) / sum(s):.0f} studies/h")
PY
