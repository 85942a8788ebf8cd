#!/usr/bin/env bash
# The renderer benchmark of issue 3 in one run: endocast and the VTK peer
# (vtkFixedPointVolumeRayCastMapper) on the SAME frames — the colon phantom at the paper's size
# (512×512×478), FRAMES cameras along its centreline, 512×512, vertical FOV 90°, step 0.5 mm,
# the same ramp and complex transfer functions (bench/tf/, opacity per mm).
#
# Usage (repository root, ../shared/peers beside it, VTK from ../shared/peers/install_vtk.sh):
#   bench/render_vs_vtk.sh [FRAMES]
# Prints endocast's table (paper protocol + the DVR runs on the peer's path), then the peer's,
# then endocast's peer-path runs again and the ratios against both (bench/ratio_table.py).
set -euo pipefail
frames=${1:-60}
out=${OUT:-bench/out}
mkdir -p "$out"
source "$(dirname "$0")/cargo_bin.sh"
endocast_binary
cargo build --release -p endocast-io --example colon_path >/dev/null
bin=$endocast
nii=$out/colon512.nii.gz
[ -f "$nii" ] || "$release_dir/examples/colon_path" --size 512 --frames "$frames" --out-dir "$out"
"$release_dir/examples/colon_path" --size 512 --frames "$frames" --out-dir "$out" --path-only
path=$out/colon512_path_lps.json
rm -f "$out/endocast.jsonl"

echo "== endocast: the paper's protocol (Tables 1 and 2) on the colon phantom"
$bin bench --phantom-size 512 --frames "$frames" --json-file "$out/endocast.jsonl"
# peer_runs FILE: endocast's runs on the peer's path and transfer functions, appended to FILE.
peer_runs() {
  for tf in ramp complex; do
    $bin bench "$nii" --path "$path" --mode dvr --tf "bench/tf/colon_$tf.json" --json-file "$1"
  done
  $bin bench "$nii" --path "$path" --mode iso --iso -500 --json-file "$1"
  $bin bench "$nii" --path "$path" --mode mip --json-file "$1"
}
echo "== endocast: the peer's runs, same path and transfer functions"
peer_runs "$out/endocast.jsonl"
echo "== VTK fixed-point CPU ray caster, same frames"
bash bench/vtk_peer.sh "$frames"
# The host's speed drifts over minutes: endocast again after the peer, the ratio against both.
echo "== endocast: the peer's runs again, after the peer"
rm -f "$out/endocast_after.jsonl"
peer_runs "$out/endocast_after.jsonl"
echo "== VTK ÷ endocast on the same frames (endocast measured before and after VTK)"
python3 bench/ratio_table.py "$out/endocast.jsonl" "$out/endocast_after.jsonl" "$out/vtk_peer.jsonl"
