#!/usr/bin/env bash
# Makes every picture README.md shows (issue 31) from the command README gives for it: runs
# README's test (crates/endocast-cli/tests/readme.rs) in its writing mode, which runs every
# command of README's sh blocks as written, in a scratch folder with ../shared/data reachable,
# and copies each docs/examples/*.png a command made over the committed one — the viewer's
# screenshot under xvfb-run too — then runs README's Python block from the repository's root
# when a Python with the endocast package is at hand ($PYTHON, default python3).
# The binary is $ENDOCAST, else the release build (bench/cargo_bin.sh).
# Usage (repository root, ../shared beside it): bench/readme_pictures.sh
set -euo pipefail
cd "$(dirname "$0")/.."
source bench/cargo_bin.sh
endocast_binary
ENDOCAST=$endocast ENDOCAST_README_PICTURES=write ENDOCAST_README_XVFB=1 \
  cargo test -q -p endocast-cli --test tests -- readme::every_readme_command_runs_as_written_and_makes_its_picture --exact --nocapture
python=${PYTHON:-python3}
if "$python" -c 'import endocast' 2>/dev/null; then
  sed -n '/^```python$/,/^```$/p' README.md | sed '1d;$d' | "$python" -
  echo "wrote docs/examples/python-trachea.png"
else
  echo "SKIPPED docs/examples/python-trachea.png: $python has no endocast package (pip install ./crates/endocast-py)"
fi
