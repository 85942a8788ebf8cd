#!/usr/bin/env bash
# Load-time benchmark: endocast vs SimpleITK's ImageSeriesReader on the same DICOM series, warm
# (files in the page cache) and cold (evicted before each run), medians by hyperfine, and peak
# resident memory by GNU time. Needs hyperfine, GNU time and `pip install SimpleITK`.
# Usage: bench/load.sh [RUNS]   (from the repository root, with ../shared/data beside it)
set -euo pipefail
runs=${1:-7}
source "$(dirname "$0")/cargo_bin.sh"
endocast_binary
bin=$endocast
here=$(dirname "$0")
for series in abdomen-ct-pancreas-dicom chest-ct-airways-dicom; do
  dir=../shared/data/$series
  echo "== $series"
  hyperfine --style basic --warmup 2 --runs "$runs" --export-json "/tmp/load-$series-warm.json" \
    -n "endocast warm" "$bin info $dir" \
    -n "SimpleITK warm" "python3 $here/sitk_load.py $dir"
  hyperfine --style basic --runs "$runs" --export-json "/tmp/load-$series-cold.json" \
    --prepare "python3 $here/evict.py $dir" \
    -n "endocast cold" "$bin info $dir" \
    -n "SimpleITK cold" "python3 $here/sitk_load.py $dir"
  for cmd in "$bin info $dir" "python3 $here/sitk_load.py $dir"; do
    rss=$(/usr/bin/time -f %M $cmd 2>&1 >/dev/null | tail -1)
    echo "peak RSS $((rss / 1024)) MiB: $cmd"
  done
done
