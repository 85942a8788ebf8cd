#!/usr/bin/env python3
"""Load a DICOM series with SimpleITK's ImageSeriesReader, the peer we compare load time with.
Usage: sitk_load.py DIR [REPEATS]. With REPEATS > 1 it also prints the median in-process load
time (file listing + Execute), to compare with endocast's in-process median. SimpleITK is a
benchmark-only tool (pip install SimpleITK), not a dependency of endocast."""
import statistics
import sys
import time

import SimpleITK as sitk


def load(folder):
    reader = sitk.ImageSeriesReader()
    reader.SetFileNames(reader.GetGDCMSeriesFileNames(folder))
    return reader.Execute()


repeats = int(sys.argv[2]) if len(sys.argv) > 2 else 1
times = []
for _ in range(repeats):
    start = time.perf_counter()
    image = load(sys.argv[1])
    times.append(time.perf_counter() - start)
print(image.GetSize(), image.GetSpacing())
if repeats > 1:
    print(f"median in-process load: {statistics.median(times):.3f} s over {repeats} runs")
