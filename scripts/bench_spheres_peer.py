#!/usr/bin/env python3
"""The peer figure for `orbcloud bench spheres`: PyVista (VTK) drawing the same synthetic atoms
(a jittered cubic lattice at 2.2 A, as orbcloud's) as sphere sprites, offscreen at 800x600, in
ms per frame while the camera turns. Run under xvfb-run where there is no display.

    python3 scripts/bench_spheres_peer.py [ATOMS...]     (default 10000 100000 1000000)
"""
import sys
import time

import numpy as np
import pyvista as pv


def atom_box(n, spacing=2.2):
    side = int(np.ceil(n ** (1 / 3)))
    i = np.arange(n)
    p = np.stack([i % side, (i // side) % side, i // (side * side)], axis=1).astype(float) - 0.5 * (side - 1)
    rng = np.random.default_rng(1)
    return (p + 0.3 * (rng.random((n, 3)) - 0.5)) * spacing


def bench(n, frames=5):
    points = atom_box(n)
    plotter = pv.Plotter(off_screen=True, window_size=(800, 600))
    cloud = pv.PolyData(points)
    cloud["z"] = np.array([6, 7, 8, 16, 1] * (n // 5 + 1))[:n]
    plotter.add_mesh(cloud, style="points_gaussian", emissive=False, render_points_as_spheres=True,
                     point_size=8, scalars="z", show_scalar_bar=False)
    plotter.show(auto_close=False)
    times = []
    for f in range(frames + 2):
        plotter.camera.azimuth += 1.0
        t = time.perf_counter()
        plotter.render()
        if f >= 2:
            times.append(time.perf_counter() - t)
    plotter.close()
    times.sort()
    print(f"pyvista {pv.__version__} (VTK {pv.vtk_version_info}) sprites: {n} atoms "
          f"ms_per_frame_median={1e3 * times[len(times) // 2]:.1f}")


if __name__ == "__main__":
    for n in [int(a) for a in sys.argv[1:]] or [10_000, 100_000, 1_000_000]:
        bench(n)
