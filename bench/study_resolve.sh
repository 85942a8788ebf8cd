#!/usr/bin/env bash
# The time to resolve a study (issue 31): for every shared scan with no preset and with each
# preset that applies to it, `endocast render --json` reports how long the study took (the
# preset in the scan's units, the structure, the start and the automatic path; the scan's
# loading and the render excluded). Prints a Markdown table of the median of RUNS runs.
# Usage (repository root, ../shared beside it): bench/study_resolve.sh [RUNS]
set -euo pipefail
runs=${1:-3}
data=../shared/data
source "$(dirname "$0")/cargo_bin.sh"
endocast_binary
bin=$endocast
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
echo "| scan | preset | structure | median ms | runs (ms) |"
echo "|---|---|---|---|---|"
while read -r scan presets; do
  for preset in none $presets; do
    flags=()
    [ "$preset" != none ] && flags=(--preset "$preset")
    times=()
    for _ in $(seq "$runs"); do
      "$bin" render "$data/$scan" "${flags[@]}" -o "$tmp/v.png" --size 16x16 --json \
        2>/dev/null >"$tmp/r.json"
      times+=("$(python3 -c 'import json,sys; print(round(json.load(open(sys.argv[1]))["study"]["resolve_ms"]))' "$tmp/r.json")")
    done
    what=$(python3 -c 'import json,sys; s=json.load(open(sys.argv[1]))["study"]; print((s["structure"] or "framed").split(":")[0] if s["confident"] or not s["structure"] else "not confident")' "$tmp/r.json")
    median=$(printf '%s\n' "${times[@]}" | sort -n | sed -n "$(( (runs + 1) / 2 ))p")
    echo "| $scan | $preset | $what | $median | ${times[*]} |"
  done
done <<'SCANS'
abdomen-ct-pancreas-dicom colonoscopy
aorta-stent-cta/stent.nrrd angioscopy
brain-mri-flair-nrrd/FLAIR.nrrd ventricles
brain-mri-t1/chris_t1.nii.gz ventricles
chest-ct-airways-dicom bronchoscopy
classic-engine-ct/engine.nii.gz
classic-vtk-headsq/quarter.nhdr sinus
head-ct-ge-gantry-tilt/GE sinus
head-ct-stanford-cthead/CThead.nhdr sinus
knee-mri/knee3D_dataR.mha arthroscopy
knee-mri/knee3D_dataT.mha arthroscopy
SCANS
