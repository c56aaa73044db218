#!/usr/bin/env python3
"""Peer benchmark: VTK's flying edges (vtkFlyingEdges3D) on a cube file's orbital.

    python3 scripts/peer_vtk_isosurface.py CUBE --iso V [--runs 20]

Extracts the two surfaces psi = +V and psi = -V in one filter run, with
normals computed from the field's gradient (as orbcloud does), and reports the
median wall time of `runs` executions (the filter is marked modified before
each). Prints `vtk_triangles=<n>` and `vtk_extract_ms=<float>`.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from peer_vtk import read_cube, to_image_data, vtk  # noqa: E402


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("cube")
    ap.add_argument("--iso", type=float, required=True)
    ap.add_argument("--runs", type=int, default=20)
    args = ap.parse_args()
    values, origin, axes, _ = read_cube(args.cube)
    image = to_image_data(values, origin, axes)
    fe = vtk.vtkFlyingEdges3D()
    fe.SetInputData(image)
    fe.SetNumberOfContours(2)
    fe.SetValue(0, args.iso)
    fe.SetValue(1, -args.iso)
    fe.ComputeNormalsOn()
    fe.ComputeGradientsOff()
    fe.ComputeScalarsOff()
    fe.Update()
    times = []
    for _ in range(max(args.runs, 1)):
        fe.Modified()
        t = time.perf_counter()
        fe.Update()
        times.append((time.perf_counter() - t) * 1e3)
    times.sort()
    print(f"vtk {vtk.vtkVersion.GetVTKVersion()} flying edges, grid {values.shape}, "
          f"SMP backend {vtk.vtkSMPTools.GetBackend()} ({vtk.vtkSMPTools.GetEstimatedNumberOfThreads()} threads)")
    print(f"vtk_triangles={fe.GetOutput().GetNumberOfCells()}")
    print(f"vtk_extract_ms={times[len(times) // 2]:.2f}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
