#!/usr/bin/env bash
# The example images of the endoscope's look (README, "The endoscope's look"): the nasal cavity
# and the right maxillary sinus of CThead through a 120° equidistant fisheye in the plain look,
# realistic without secretion and realistic with it; a lateral ventricle of the T1 MRI and the
# trachea of the chest CT, realistic. Each realistic image averages 8 jittered passes (--still).
# Poses: bench/scenes.json (nasal cavity, ventricle, trachea); the maxillary sinus's eye sits in
# the sinus's anteromedial part (slice 60, index 84,60) looking back and out along its floor.
# Usage (repository root, ../shared beside it): bench/look_examples.sh [OUT_DIR]
set -euo pipefail
out=${1:-docs/examples}
data=../shared/data
source "$(dirname "$0")/cargo_bin.sh"
endocast_binary
bin=$endocast
head=("$data/head-ct-stanford-cthead/CThead.nhdr" --orientation LPI --preset sinus)
fisheye=(--lens equidistant --fov 120 --size 512x512)
nasal=(--eye 104,44,-120 --look-at 104,63.779,-122.967 --up 0,0,1)
maxillary=(--eye 84,60,-120 --look-at 74,76,-124 --up 0,0,1)
for view in nasal maxillary; do
  declare -n pose=$view
  $bin render "${head[@]}" "${fisheye[@]}" "${pose[@]}" -o "$out/look-$view-plain.png"
  $bin render "${head[@]}" "${fisheye[@]}" "${pose[@]}" --look realistic --secretion off \
    --still 8 -o "$out/look-$view-dry.png"
  $bin render "${head[@]}" "${fisheye[@]}" "${pose[@]}" --look realistic --secretion on \
    --still 8 -o "$out/look-$view-secretion.png"
done
$bin render "$data/brain-mri-t1/chris_t1.nii.gz" --preset ventricles --look realistic --still 8 \
  --eye 16.24,31.88,17.04 --look-at 12.055,12.348,18.037 --up 0,0,1 --fov 100 \
  -o "$out/look-ventricle-realistic.png"
$bin render "$data/chest-ct-airways-dicom" --preset bronchoscopy --look realistic --still 8 \
  --eye=-9.84,66.32,51.5 --look-at=-17.58,72.5,15.5 --up 0,-1,0 \
  -o "$out/look-trachea-realistic.png"
