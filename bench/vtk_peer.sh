#!/usr/bin/env bash
# The VTK peer (vtkFixedPointVolumeRayCastMapper, VTK's multithreaded CPU ray caster) on the
# colon fly-through of the renderer benchmark: the colon phantom at the paper's size
# (512×512×478, 1 mm), FRAMES cameras along its centreline, 512×512, vertical FOV 90°, step 0.5 mm.
# Modes: DVR with the simple ramp and the complex TF (bench/tf/, shading off as behind the
# paper's isosurface, and on), iso (the peer's step-TF emulation at ISO HU) and MIP.
#
# Usage (from the repository root, ../shared/peers beside it, VTK installed by
# ../shared/peers/install_vtk.sh):   bench/vtk_peer.sh [FRAMES]
# Writes $OUT/colon512.nii.gz and the camera paths (crates/endocast-io/examples/colon_path.rs;
# the same cameras in our LPS world as colon512_path_lps.json for `endocast`), first/last frame
# PNGs and one JSON line per run in $OUT/vtk_peer.jsonl (label = run name and the 1-minute load
# average before it: compare cpu_util with the README's quiet-run range 1.85–1.97).
set -euo pipefail
frames=${1:-60}
size=${SIZE:-512}
iso=${ISO:--500}
out=${OUT:-bench/out}
peers=${PEERS:-../shared/peers}
py=${PY:-/opt/peers-venv/bin/python}
export VTK_DEFAULT_OPENGL_WINDOW=vtkEGLRenderWindow

source "$(dirname "$0")/cargo_bin.sh"
cargo build --release -p endocast-io --example colon_path >/dev/null
nii=$out/colon$size.nii.gz
if [ -f "$nii" ]; then
  "$release_dir/examples/colon_path" --size "$size" --frames "$frames" --out-dir "$out" --path-only
else
  "$release_dir/examples/colon_path" --size "$size" --frames "$frames" --out-dir "$out"
fi
path=$out/colon${size}_path_vtk.txt
results=$out/vtk_peer.jsonl
rm -f "$results"

# run NAME ARGS...: one peer run over the whole path, appended to $results.
run() {
  local name=$1
  shift
  local load
  load=$(cut -d' ' -f1 /proc/loadavg)
  "$py" "$peers/vtk_render.py" "$nii" --path "$path" --mapper fixedpoint \
    --view-angle 90 --size 512 512 --sample-distance 0.5 \
    --out "$out/vtk_$name" --json "$results" --label "colon$size $name load=$load" "$@" |
    grep -E "first frame|cpu utilisation|non-background"
}

run dvr-ramp --mode dvr --tf bench/tf/colon_ramp.json --shade off
run dvr-ramp-shaded --mode dvr --tf bench/tf/colon_ramp.json --shade on
run dvr-complex --mode dvr --tf bench/tf/colon_complex.json --shade off
run dvr-complex-shaded --mode dvr --tf bench/tf/colon_complex.json --shade on
run iso --mode iso --iso "$iso" --shade on
run mip --mode mip

python3 "$peers/make_table.py" "$results"
