"""PSNR table of bench/quality_psnr.sh: reads its images.tsv (scan, mode, column, reference
PNG, image PNG), prints a Markdown table of PSNR in dB (8-bit RGB, peak 255; "=" where the
images are identical) per scan and mode, one column per build, and flags values under 40 dB."""

import math
import sys
from collections import OrderedDict

import numpy as np
from PIL import Image


def psnr(reference: str, image: str) -> float:
    a = np.asarray(Image.open(reference).convert("RGB"), dtype=np.float64)
    b = np.asarray(Image.open(image).convert("RGB"), dtype=np.float64)
    if a.shape != b.shape:
        raise SystemExit(f"{image}: size {b.shape} differs from the reference's {a.shape}")
    mse = float(np.mean((a - b) ** 2))
    return math.inf if mse == 0.0 else 10.0 * math.log10(255.0**2 / mse)


def main(path: str) -> None:
    rows: "OrderedDict[tuple, dict]" = OrderedDict()
    columns: list = []
    with open(path, encoding="utf-8") as lines:
        for line in lines:
            scan, mode, column, reference, image = line.rstrip("\n").split("\t")
            if column not in columns:
                columns.append(column)
            rows.setdefault((scan, mode), {})[column] = psnr(reference, image)
    print("| scan | mode | " + " | ".join(f"{c}, dB" for c in columns) + " |")
    print("|---|---|" + "---:|" * len(columns))
    for (scan, mode), values in rows.items():
        cells = []
        for c in columns:
            v = values.get(c)
            if v is None:
                cells.append("—")
            elif math.isinf(v):
                cells.append("=")
            else:
                cells.append(f"{v:.1f}" + (" **<40**" if v < 40.0 else ""))
        print(f"| {scan} | {mode} | " + " | ".join(cells) + " |")


if __name__ == "__main__":
    main(sys.argv[1])
