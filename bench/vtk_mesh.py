"""VTK's isosurface extraction on a NIfTI volume, for `bench/mesh_vs_vtk.sh`.

Runs vtkFlyingEdges3D (and, with --from, keeps the connected surface closest to a point, as
`endocast mesh --from` does) several times and prints one JSON line: median wall and CPU seconds, triangles,
vertices. The isovalue is physical (the NIfTI rescale is applied); VTK's NIfTI reader ignores the
affine, so --from is given in voxel indices.
"""
import argparse
import json
import statistics
import time

import vtk


def main():
    p = argparse.ArgumentParser()
    p.add_argument("volume")
    p.add_argument("--iso", type=float, required=True)
    p.add_argument("--from-ijk", type=float, nargs=3)
    p.add_argument("--runs", type=int, default=3)
    a = p.parse_args()
    reader = vtk.vtkNIFTIImageReader()
    reader.SetFileName(a.volume)
    reader.Update()
    slope = reader.GetRescaleSlope() or 1.0
    stored_iso = (a.iso - reader.GetRescaleIntercept()) / slope
    times, cpu, mesh = [], [], None
    for _ in range(a.runs):
        start, start_cpu = time.perf_counter(), time.process_time()
        fe = vtk.vtkFlyingEdges3D()
        fe.SetInputConnection(reader.GetOutputPort())
        fe.SetValue(0, stored_iso)
        fe.ComputeNormalsOff()
        fe.ComputeGradientsOff()
        fe.ComputeScalarsOff()
        last = fe
        if a.from_ijk:
            spacing = reader.GetOutput().GetSpacing()
            conn = vtk.vtkPolyDataConnectivityFilter()
            conn.SetInputConnection(fe.GetOutputPort())
            conn.SetExtractionModeToClosestPointRegion()
            conn.SetClosestPoint(*[c * s for c, s in zip(a.from_ijk, spacing)])
            last = conn
        last.Update()
        times.append(time.perf_counter() - start)
        cpu.append(time.process_time() - start_cpu)
        mesh = last.GetOutput()
    print(json.dumps({
        "peer": "vtkFlyingEdges3D" + (" + connectivity" if a.from_ijk else ""),
        "volume": a.volume,
        "iso": a.iso,
        "median_s": statistics.median(times),
        "runs_s": times,
        "median_cpu_s": statistics.median(cpu),
        "triangles": mesh.GetNumberOfPolys(),
        "vertices": mesh.GetNumberOfPoints(),
        "smp_backend": vtk.vtkSMPTools.GetBackend(),
    }))


if __name__ == "__main__":
    main()
