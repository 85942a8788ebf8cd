#!/usr/bin/env bash
# B-spline still ÷ trilinear still per frame (issue 35 item 6) on CThead, 512²: the sinus
# preset's realistic look and its plain hybrid view. Per round and filter, `render --still 1`
# and `--still FRAMES` (--json time_ms: the frames' render time, no loading); a frame's cost is
# (T_FRAMES − T_1) / (FRAMES − 1), which leaves out the one-off B-spline coefficients (built by
# the first spline frame). Filters interleaved within a round; medians of the per-round ratios.
# Usage: bench/spline_still.sh [ROUNDS] [FRAMES]   (from the repository root)
set -euo pipefail
rounds=${1:-3}
frames=${2:-3}
source "$(dirname "$0")/cargo_bin.sh"
endocast_binary
scan=${DATA:-/work/shared/data}/head-ct-stanford-cthead/CThead.nhdr
out=$(mktemp -d)
time_ms() { "$endocast" render "$scan" --orientation LPI --preset sinus --size 512x512 \
  -o "$out/view.png" --json "$@" 2>/dev/null | python3 -c 'import json,sys; print(json.load(sys.stdin)["time_ms"])'; }
echo "view round filter t1_ms tN_ms"
for view in realistic hybrid; do
  case $view in
    realistic) args=(--look realistic) ;;
    hybrid) args=(--look plain --mode hybrid) ;;
  esac
  for round in $(seq "$rounds"); do
    for filter in trilinear bspline; do
      t1=$(time_ms "${args[@]}" --still 1 --still-filter $filter)
      tn=$(time_ms "${args[@]}" --still "$frames" --still-filter $filter)
      echo "$view $round $filter $t1 $tn"
    done
  done
done | tee "$out/times.txt"
python3 - "$out/times.txt" "$frames" <<'PY'
import sys, statistics
rows = [l.split() for l in open(sys.argv[1]).read().splitlines() if not l.startswith("view")]
n = int(sys.argv[2])
per = {}
for view, rnd, f, t1, tn in rows:
    per[(view, rnd, f)] = ((float(tn) - float(t1)) / (n - 1), float(t1), float(tn))
for view in sorted({r[0] for r in rows}):
    rounds = sorted({r[1] for r in rows if r[0] == view})
    frame = {f: statistics.median(per[(view, r, f)][0] for r in rounds) for f in ("trilinear", "bspline")}
    ratio = statistics.median(per[(view, r, "bspline")][0] / per[(view, r, "trilinear")][0] for r in rounds)
    build = statistics.median(per[(view, r, "bspline")][1] - per[(view, r, "bspline")][0] for r in rounds)
    whole = statistics.median(per[(view, r, "bspline")][2] / per[(view, r, "trilinear")][2] for r in rounds)
    print(f"{view}: frame trilinear {frame['trilinear']:.0f} ms, bspline {frame['bspline']:.0f} ms, "
          f"ratio {ratio:.2f}x; first spline frame's extra (coefficients) {build:.0f} ms; "
          f"whole {n}-frame still {whole:.2f}x")
PY
