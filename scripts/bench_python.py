"""Timings of the Python package, each against its peer in the same run:
- `Document.evaluate` on 10⁶ points against PySCF's `eval_gto` followed by the matrix product
  with the orbital's coefficients (one orbital, and every occupied orbital for the density);
- the notebook viewer's frame (`Scene.draw`, what the widget sends per mouse move) at 600×450.

Run with the package installed (`pip install .`):  python3 scripts/bench_python.py [--lavapipe]
"""

import argparse
import os
import time

import numpy as np
from pyscf import gto, lib, scf

import orbcloud
from orbcloud import _native


def best(f, repeat=3):
    times = []
    for _ in range(repeat):
        t = time.perf_counter()
        f()
        times.append(time.perf_counter() - t)
    return min(times)


MOLECULES = {
    "water 6-31G*": ("O 0 0 0.117; H 0 0.757 -0.467; H 0 -0.757 -0.467", "6-31g*"),
    "benzene 6-31G*": (
        "; ".join(
            f"{e} {r * np.cos(a):.6f} {r * np.sin(a):.6f} 0"
            for k in range(6)
            for e, r, a in [("C", 1.39, k * np.pi / 3), ("H", 2.47, k * np.pi / 3)]
        ),
        "6-31g*",
    ),
}


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--points", type=int, default=1_000_000)
    parser.add_argument("--lavapipe", action="store_true")
    args = parser.parse_args()
    print(f"cores: {os.cpu_count()}, PySCF threads: {lib.num_threads()}")
    rng = np.random.default_rng(0)
    for name, (atom, basis) in MOLECULES.items():
        mol = gto.M(atom=atom, basis=basis, verbose=0)
        mf = scf.RHF(mol).run()
        doc = orbcloud.from_pyscf(mf)
        points = rng.normal(scale=3.0, size=(args.points, 3))
        homo = int(np.flatnonzero(mf.mo_occ > 0)[-1])
        ours = best(lambda: doc.evaluate(points, "homo"))
        theirs = best(lambda: mol.eval_gto("GTOval", points) @ mf.mo_coeff[:, homo])
        occupied = mf.mo_coeff[:, mf.mo_occ > 0]

        def pyscf_density():
            mo = mol.eval_gto("GTOval", points) @ occupied
            return 2.0 * np.einsum("pi,pi->p", mo, mo)

        ours_rho = best(lambda: doc.density(points))
        theirs_rho = best(pyscf_density)
        err = np.abs(doc.evaluate(points[:10000], "homo") - mol.eval_gto("GTOval", points[:10000]) @ mf.mo_coeff[:, homo]).max()
        print(
            f"{name} ({mol.nao_nr()} AOs), {args.points:,} points: HOMO orbcloud {ours:.3f} s, PySCF eval_gto+matmul {theirs:.3f} s;"
            f" density orbcloud {ours_rho:.3f} s, PySCF {theirs_rho:.3f} s; max |difference| {err:.1e}"
        )
    water = orbcloud.from_pyscf(scf.RHF(gto.M(atom=MOLECULES["water 6-31G*"][0], basis="6-31g*", verbose=0)).run())
    words = orbcloud._words({"size": (600, 450), "orbital": "homo", "iso": 0.05, "no_volume": True, "lavapipe": args.lavapipe})
    scene = _native.Scene(water._native, words)
    for _ in range(3):
        scene.orbit(0.02, 0.0)
        scene.draw()
    times = []
    for _ in range(20):
        scene.orbit(0.02, 0.01)
        t = time.perf_counter()
        scene.draw()
        times.append(time.perf_counter() - t)
    times.sort()
    print(f"notebook frame 600x450, water HOMO isosurfaces: median {1e3 * times[10]:.1f} ms (min {1e3 * times[0]:.1f}, max {1e3 * times[-1]:.1f})")


if __name__ == "__main__":
    main()
