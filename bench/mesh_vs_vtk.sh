#!/usr/bin/env bash
# `endocast mesh` against VTK's flying edges (issue 19, item 4) on the same volumes and
# isovalues: the whole volume's isosurface, and the connected lumen around a point
# (endocast: --from; VTK: flying edges + vtkPolyDataConnectivityFilter, closest region).
# Prints one line per run: wall and CPU seconds (median of RUNS), triangles, vertices.
#
# Usage (repository root, VTK from ../shared/peers/install_vtk.sh; SHARED_DATA: the shared
# data folder when it is not ../shared/data):
#   bench/mesh_vs_vtk.sh [RUNS]
#
# The extraction alone, interleaved with VTK (issue 33, item 6): each round runs, per phantom,
# `isosurface()` (the `mesh_extraction` example on one thread: mean CPU of 20 runs), then the
# same with the example in $BEFORE when set (another build, e.g. an older commit's), then VTK's
# flying edges (SMP backend "Sequential": one thread; median CPU of 20 runs); the last lines are
# the medians over the rounds and the median of the per-round ratios endocast ÷ VTK.
#   bench/mesh_vs_vtk.sh extraction [ROUNDS]
set -euo pipefail
out=${OUT:-bench/out}
py=${VTK_PYTHON:-/opt/peers-venv/bin/python}
mkdir -p "$out"
source "$(dirname "$0")/cargo_bin.sh"
endocast_binary
bin=$endocast
if [ "${1:-}" = extraction ]; then
  mode=extraction
  rounds=${2:-5}
else
  mode=command
  runs=${1:-3}
fi
colon=$out/colon256.nii.gz
[ -f "$colon" ] || $bin phantom colon --size 256 -o "$colon" >/dev/null
sphere=$out/sphere256.nii.gz
[ -f "$sphere" ] || $bin phantom sphere-shell --size 256 -o "$sphere" >/dev/null
tube=$out/curvedtube256.nii.gz
[ -f "$tube" ] || $bin phantom curved-tube --size 256 -o "$tube" >/dev/null
cthead=$out/cthead.nii.gz
[ -f "$cthead" ] || $bin convert "${SHARED_DATA:-../shared/data}"/head-ct-stanford-cthead/CThead.nhdr -o "$cthead" >/dev/null

# extraction_rounds: the interleaved rounds of the extraction alone (see the usage above).
extraction_rounds() {
  cargo build --release -q -p endocast-core --example mesh_extraction
  local example=$release_dir/examples/mesh_extraction log=$out/extraction.txt
  : >"$log"
  for round in $(seq "$rounds"); do
    for p in colon:$colon sphere-shell:$sphere curved-tube:$tube; do
      local name=${p%%:*} file=${p#*:}
      for build in after ${BEFORE:+before}; do
        local exe=$example
        [ "$build" = before ] && exe=$BEFORE
        RAYON_NUM_THREADS=1 "$exe" "$name" 256 -500 20 |
          sed -n "s/.*: \([0-9]*\) triangles.*CPU \([0-9.]*\) s each.*/$round $name $build \2 \1/p" >>"$log"
      done
      "$py" bench/vtk_mesh.py "$file" --iso -500 --runs 20 | python3 -c "import json, sys
d = json.load(sys.stdin)
print($round, '$name', 'vtk', d['median_cpu_s'], d['triangles'], d['smp_backend'])" >>"$log"
    done
    tail -n "$((3 * (${BEFORE:+1} + 2)))" "$log"
  done
  python3 - "$log" <<'PY'
import collections, statistics, sys
cpu = collections.defaultdict(dict)
for line in open(sys.argv[1]):
    r, name, build, s = line.split()[:4]
    cpu[(name, build)][r] = float(s)
for name in ("colon", "sphere-shell", "curved-tube"):
    builds = [b for b in ("before", "after", "vtk") if (name, b) in cpu]
    medians = ", ".join(f"{b} {statistics.median(cpu[(name, b)].values()):.4f} s" for b in builds)
    ratios = lambda b: [cpu[(name, b)][r] / cpu[(name, "vtk")][r] for r in cpu[(name, "vtk")]]
    told = ", ".join(f"{b} ÷ vtk {statistics.median(ratios(b)):.2f} (rounds {min(ratios(b)):.2f}–{max(ratios(b)):.2f})"
                     for b in builds if b != "vtk")
    print(f"{name}: CPU medians {medians}; median of the rounds' ratios: {told}")
PY
}

# endocast_runs VOLUME ISO [X,Y,Z]: median wall and CPU seconds of `endocast mesh`.
endocast_runs() {
  local from=() walls=() cpus=()
  [ -n "${3:-}" ] && from=(--from "$3")
  for _ in $(seq "$runs"); do
    /usr/bin/time -f "%e %U %S" -o "$out/time.txt" \
      $bin mesh "$1" --iso "$2" "${from[@]}" -o "$out/mesh.stl" >"$out/mesh.txt"
    read -r wall user sys <"$out/time.txt"
    walls+=("$wall"); cpus+=("$(echo "$user + $sys" | bc)")
  done
  printf 'endocast mesh %s --iso %s %s: wall %s s, CPU %s s (medians of %s); %s\n' "$1" "$2" \
    "${from[*]}" "$(printf '%s\n' "${walls[@]}" | sort -n | sed -n "$(((runs + 1) / 2))p")" \
    "$(printf '%s\n' "${cpus[@]}" | sort -n | sed -n "$(((runs + 1) / 2))p")" "$runs" \
    "$(cat "$out/mesh.txt")"
}

if [ "$mode" = extraction ]; then
  extraction_rounds
  exit
fi

echo "== colon phantom 256 (256×256×239, 1 mm), −500 HU"
endocast_runs "$colon" -500
"$py" bench/vtk_mesh.py "$colon" --iso -500 --runs "$runs"
endocast_runs "$colon" -500 56.5,-11.5,-18
"$py" bench/vtk_mesh.py "$colon" --iso -500 --runs "$runs" --from-ijk 184 116 101
# There is no torus phantom: the curved tube (a tube bent through 270° around a circle, closed
# by half balls) is the nearest.
echo "== sphere-shell phantom 256 (256³, 1 mm), −500 HU; --from the centre (the inner air)"
endocast_runs "$sphere" -500
"$py" bench/vtk_mesh.py "$sphere" --iso -500 --runs "$runs"
endocast_runs "$sphere" -500 0,0,0
"$py" bench/vtk_mesh.py "$sphere" --iso -500 --runs "$runs" --from-ijk 128 128 128
echo "== curved-tube phantom 256 (256³, 1 mm), −500 HU; --from a point of its axis"
endocast_runs "$tube" -500
"$py" bench/vtk_mesh.py "$tube" --iso -500 --runs "$runs"
endocast_runs "$tube" -500 76.8,0,0
"$py" bench/vtk_mesh.py "$tube" --iso -500 --runs "$runs" --from-ijk 204 128 128
echo "== CThead (256×256×113, 1×1×2 mm), skin/air at 550 (stored, about −470 HU)"
endocast_runs "$cthead" 550
"$py" bench/vtk_mesh.py "$cthead" --iso 550 --runs "$runs"
