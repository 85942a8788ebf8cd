#!/usr/bin/env python3
"""The endocast/VTK ratio of bench/render_vs_vtk.sh, robust to the host's drift: endocast's four
peer-path runs are measured before AND after the VTK runs, and each ratio is VTK's median frame
time over the mean of endocast's two medians (with the range the two give on their own).

Usage: ratio_table.py BEFORE.jsonl AFTER.jsonl VTK.jsonl
(BEFORE: its last four lines are the peer-path runs DVR ramp, DVR complex, iso, MIP, in that
order, as render_vs_vtk.sh writes them; AFTER: the same four runs; VTK: vtk_peer.sh's lines.)"""
import json
import statistics
import sys

RUNS = [("DVR, ramp TF, unshaded", "dvr-ramp"), ("DVR, complex TF, unshaded", "dvr-complex"),
        ("iso −500 HU (VTK: step TF)", "iso"), ("MIP", "mip")]


def medians(path, last):
    lines = [json.loads(line) for line in open(path) if line.strip()][-last:]
    return [statistics.median(run["ms"]) for run in lines]


def main():
    before = medians(sys.argv[1], len(RUNS))
    after = medians(sys.argv[2], len(RUNS))
    vtk = {}
    for line in open(sys.argv[3]):
        run = json.loads(line)
        vtk[run["label"].split()[1]] = run["render_ms"]["median"]
    print("| mode | endocast before / after, median ms | VTK median ms | VTK ÷ endocast (range) |")
    print("|---|---|---|---|")
    for (name, key), b, a in zip(RUNS, before, after):
        v = vtk[key]
        mean = (a + b) / 2
        print(f"| {name} | {b:.1f} / {a:.1f} | {v:.1f} | **{v / mean:.2f}×** "
              f"({v / max(a, b):.2f}–{v / min(a, b):.2f}) |")


if __name__ == "__main__":
    main()
