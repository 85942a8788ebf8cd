#!/usr/bin/env bash
# Flight paths inside the shared real scans, made by `endocast path` from fixed end points
# (world mm, LPS; the starts are the acceptance poses of bench/scenes.json):
#   trachea    chest-ct-airways-dicom: from the upper trachea to the farthest airway point
#              (down through the carina into the left main bronchus), airway lumen < −900 HU
#   aorta      abdomen-ct-pancreas-dicom: the enhanced aorta from above the renal arteries down
#              150 mm (end point read off the axial slices), lumen > 130 HU
#   nasal      head-ct-stanford-cthead: the sinus preset's own path, back along the nasal
#              airway from its start (read upright as LPI; the passages wide enough for a 1 mm
#              endoscope, cut from the air outside at the nostrils)
#   ventricle  brain-mri-t1: 32 mm along the left lateral ventricle towards the frontal horn
# Usage (repository root, ../shared beside it): bench/real_paths.sh [OUT_DIR]
# The ventricles' CSF threshold also takes the dark background of a T1 scan, so that path needs
# an end point ("to the farthest point" would leave the structure) and, from this start in the
# left lateral ventricle, a threshold of 60: at the preset's 75 (and at 69.7, where the finder
# closed the right one) the CSF there still joins the background. The nasal cavity opens to the
# air outside at the nostrils: a threshold lumen from a point there leaks out of the head (and is
# refused), so its path is the preset's, planned in the structure it finds.
set -euo pipefail
out=${1:-bench/out/paths}
data=../shared/data
mkdir -p "$out"
source "$(dirname "$0")/cargo_bin.sh"
endocast_binary
bin=$endocast
$bin path "$data/chest-ct-airways-dicom" --preset bronchoscopy \
  --from -9.84,66.32,51.5 -o "$out/trachea.json"
$bin path "$data/abdomen-ct-pancreas-dicom" --preset angioscopy \
  --from 27.55,113.71,355.91 --to 11.8,76.5,205.9 -o "$out/aorta.json"
$bin path "$data/head-ct-stanford-cthead/CThead.nhdr" --preset sinus -o "$out/nasal.json"
$bin path "$data/brain-mri-t1/chris_t1.nii.gz" --preset ventricles --lumen-threshold 60 \
  --from 16.24,31.88,17.04 --to 9.55,0.65,18.6 -o "$out/ventricle.json"
