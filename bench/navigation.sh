#!/usr/bin/env bash
# The navigation benchmark of issue 4 in one run:
#   1. the colon phantom at the paper's size (512×512×478): lumen flood fill, exact distance
#      field and centred path end to end, with time and memory (example navigate_colon);
#   2. the real scans: `endocast path` (lumen + distance field + centreline + smoothing) for the
#      paths of bench/real_paths.sh;
#   3. fly-through throughput on the colon phantom, endoscope and dashboard layouts, 512×512;
#   4. memory of a 1000-frame flight against a 100-frame one (bounded memory).
# Usage (repository root, ../shared beside it): bench/navigation.sh [RUNS]
set -euo pipefail
runs=${1:-3}
out=${OUT:-bench/out}
mkdir -p "$out/nav"
source "$(dirname "$0")/cargo_bin.sh"
endocast_binary
cargo build --release -q -p endocast-core --example navigate_colon
bin=$endocast

echo "== 1. colon phantom 512×512×478 ($runs runs)"
for _ in $(seq "$runs"); do "$release_dir/examples/navigate_colon" 512; done

echo "== 2. real scans: endocast path ($runs runs)"
for _ in $(seq "$runs"); do bench/real_paths.sh "$out/paths" 2>/dev/null; done

echo "== 3. fly-through throughput, colon phantom, 512×512, colonoscopy preset"
colon=$out/colon512.nii.gz
[ -f "$colon" ] || $bin phantom colon --size 512 -o "$colon"
# The colon's two ends: the first and last camera of the renderer benchmark's path.
[ -f "$out/colon512_path_lps.json" ] || {
  cargo build --release -q -p endocast-io --example colon_path
  "$release_dir/examples/colon_path" --size 512 --frames 60 --out-dir "$out" --path-only
}
read -r from to < <(python3 -c "
import json, sys
p = json.load(open('$out/colon512_path_lps.json'))
f = lambda v: ','.join('%.2f' % c for c in v)
print(f(p[0]['eye']), f(p[-1]['eye']))")
$bin path "$colon" --preset colonoscopy --from "$from" --to "$to" -o "$out/nav/colon.json"
for layout in endoscope dashboard; do
  for _ in $(seq "$runs"); do
    $bin fly "$colon" --path "$out/nav/colon.json" --preset colonoscopy --layout $layout \
      --size 512x512 --frame-step 20 -o "$out/nav/colon_$layout.mp4" 2>/dev/null
  done
done

echo "== 4. memory: 100 and 1000 frames (128×128 endoscope, GIF)"
for step in 13 1.3; do
  /usr/bin/time -f "frame step $step mm: peak RSS %M KiB, %e s" \
    $bin fly "$colon" --path "$out/nav/colon.json" --preset colonoscopy --mode iso \
    --size 128x128 --frame-step $step -o "$out/nav/colon_memory.gif" 2>&1 >/dev/null | tail -n 1
done
