#!/usr/bin/env bash
# Image quality of every mode at its default step (issue 33): PSNR against a reference rendered
# at step 0.125 voxel, for the baseline binary and this build, on the colon phantom
# (512×512×478, the paper's size) and the chest CT, 512×512, vertical FOV 90°.
#
# Usage (repository root):
#   BASELINE=/path/to/old/endocast bench/quality_psnr.sh [NAME=FLAGS ...]
# Each NAME=FLAGS adds a column: this build with those extra flags (e.g.
# "pi4=--dvr-stride 4"). ENDOCAST picks this build's binary (default: the release build),
# SHARED_DATA the scans' folder (default ../shared/data, else /work/shared/data).
# The reference of each image is the baseline's at --step 0.125: both builds are measured
# against the same picture (add "new@0.125=--step 0.125" to see this build's own).
set -euo pipefail
out=${OUT:-bench/out}/quality
mkdir -p "$out"
source "$(dirname "$0")/cargo_bin.sh"
endocast_binary
new=$endocast
base=${BASELINE:?set BASELINE to the baseline endocast binary}
data=${SHARED_DATA:-../shared/data}
[ -d "$data" ] || data=/work/shared/data
colon=$out/colon512.nii.gz
[ -f "$colon" ] || "$new" phantom colon --size 512 -o "$colon" >/dev/null

# scan name, path, camera (the colonoscopy and bronchoscopy presets' automatic starts).
scans=(
  "colon|$colon|--eye 113.5,-23.5,-35.5 --look-at 119.88,-16.2,-33.58 --up 0.71,-0.67,0.21"
  "chest|$data/chest-ct-airways-dicom|--eye -18.55,72.33,11.5 --look-at -13.72,75.03,3.18 --up 0.14,-0.96,-0.23"
)
modes=(
  "iso|--mode iso"
  "dvr ramp|--mode dvr --tf ramp"
  "dvr complex|--mode dvr --tf complex"
  "hybrid 80% ramp|--mode hybrid --tf ramp --iso-opacity 0.8"
  "hybrid 50% ramp|--mode hybrid --tf ramp --iso-opacity 0.5"
  "hybrid 0% ramp|--mode hybrid --tf ramp --iso-opacity 0"
  "hybrid 80% complex|--mode hybrid --tf complex --iso-opacity 0.8"
  "hybrid 50% complex|--mode hybrid --tf complex --iso-opacity 0.5"
  "hybrid 0% complex|--mode hybrid --tf complex --iso-opacity 0"
  "mip|--mode mip"
)
columns=("baseline=$base|" "new=$new|")
for extra in "$@"; do columns+=("${extra%%=*}=$new|${extra#*=}"); done
rm -f "$out/images.tsv"
for scan in "${scans[@]}"; do
  IFS='|' read -r sname path camera <<<"$scan"
  for mode in "${modes[@]}"; do
    IFS='|' read -r mname flags <<<"$mode"
    common="$path --iso -500 --fov 90 --size 512x512 --look plain $camera $flags"
    tag=$(echo "$sname-$mname" | tr -c 'a-z0-9\n' '_')
    ref=$out/$tag-reference.png
    # shellcheck disable=SC2086
    "$base" render $common --step 0.125 -o "$ref" >/dev/null 2>&1
    for column in "${columns[@]}"; do
      cname=${column%%=*}
      rest=${column#*=}
      bin=${rest%%|*}
      extra=${rest#*|}
      image=$out/$tag-$(echo "$cname" | tr -c 'a-z0-9@.\n' '_').png
      # shellcheck disable=SC2086
      "$bin" render $common $extra -o "$image" >/dev/null 2>&1
      printf '%s\t%s\t%s\t%s\t%s\n' "$sname" "$mname" "$cname" "$ref" "$image" >>"$out/images.tsv"
    done
  done
done
"${PYTHON:-python3}" "$(dirname "$0")/psnr_table.py" "$out/images.tsv"
