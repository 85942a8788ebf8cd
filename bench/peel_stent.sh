#!/usr/bin/env bash
# Depth peeling against the isosurface on a real scan (issue 19): 30 cameras in the stented
# aorta of ../shared/data/aorta-stent-cta, one every 2 mm from slice 100 to 158, each looking
# posterior at the vertebra behind the wall, 512×512, 90°. Rounds of: iso at 150 (the near
# wall), peel 1 and peel last at 150 (front discarded), the docs' peel (35 % of the front kept
# through the angioscopy TF, context for unpeeled rays), and the angioscopy preset (two-iso).
# Usage: bench/peel_stent.sh [ROUNDS]   (from the repository root)
set -euo pipefail
rounds=${1:-2}
source "$(dirname "$0")/cargo_bin.sh"
endocast_binary
scan=../shared/data/aorta-stent-cta/stent.nrrd
path=$(mktemp --suffix=.json)
trap 'rm -f "$path"' EXIT
python3 -c "import json; print(json.dumps([{'eye': [65, 49, k], 'look_at': [65, 100, k], 'up': [0, 0, 1]} for k in range(100, 160, 2)]))" >"$path"
run() { "$endocast" bench "$scan" --path "$path" "$@" 2>/dev/null | tail -1; }
for _ in $(seq "$rounds"); do
  run --mode iso --iso 150
  run --mode peel --peel-threshold 150
  run --mode peel --peel-threshold 150 --peel last
  run --mode peel --peel-threshold 150 --tf angioscopy --peel-keep 0.35 --unpeeled context
  run --preset angioscopy
done
