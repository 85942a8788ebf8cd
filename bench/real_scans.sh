#!/usr/bin/env bash
# The renderer along a path inside each real scan of issue 3's acceptance renders: 60 cameras
# spread along the paths of bench/real_paths.sh (10 mm look-ahead), 512×512, 90°, each scan's
# preset, then the same frames as an opaque isosurface.
# Usage (repository root, ../shared beside it): bench/real_scans.sh [FRAMES]
set -euo pipefail
frames=${1:-60}
out=${OUT:-bench/out}
data=../shared/data
[ -f "$out/paths/ventricle.json" ] || bench/real_paths.sh "$out/paths"
source "$(dirname "$0")/cargo_bin.sh"
endocast_binary
bin=$endocast
run() { # scan path preset [options]
  local scan=$1 path=$2 preset=$3
  shift 3
  $bin bench "$data/$scan" --path "$out/paths/$path.json" --frames "$frames" --preset "$preset" "$@"
  $bin bench "$data/$scan" --path "$out/paths/$path.json" --frames "$frames" --preset "$preset" --mode iso "$@"
}
run chest-ct-airways-dicom trachea bronchoscopy
run abdomen-ct-pancreas-dicom aorta angioscopy
run head-ct-stanford-cthead/CThead.nhdr nasal sinus --orientation LPI --iso 550
run brain-mri-t1/chris_t1.nii.gz ventricle ventricles
