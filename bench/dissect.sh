#!/usr/bin/env bash
# The dissection image's time (issue 36): `endocast dissect --preset colonoscopy` on the colon
# phantom at 512³ (written once to $COLON, default /tmp/colon512.nii.gz, and reused), the time
# of the rays and the image alone (`dissect_ms`: no loading, no path planning). Prints the
# median of RUNS runs and the load. Usage (repository root): bench/dissect.sh [RUNS]
set -euo pipefail
runs=${1:-3}
colon=${COLON:-/tmp/colon512.nii.gz}
source "$(dirname "$0")/cargo_bin.sh"
endocast_binary
bin=$endocast
[ -f "$colon" ] || "$bin" phantom colon --size 512 -o "$colon"
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
times=()
for _ in $(seq "$runs"); do
  "$bin" dissect "$colon" --preset colonoscopy -o "$tmp/flat.png" --json 2>/dev/null >"$tmp/r.json"
  times+=("$(python3 -c 'import json,sys; print(round(json.load(open(sys.argv[1]))["dissect_ms"]))' "$tmp/r.json")")
done
python3 -c 'import json,sys; r=json.load(open(sys.argv[1])); print("image %dx%d, path %.0f mm" % (r["width"], r["height"], r["path_length_mm"]))' "$tmp/r.json"
median=$(printf '%s\n' "${times[@]}" | sort -n | sed -n "$(( (runs + 1) / 2 ))p")
echo "dissect_ms median $median (runs: ${times[*]}); $(nproc) cores, load: $(uptime | sed 's/.*average: //')"
