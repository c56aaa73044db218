#!/usr/bin/env python3
"""Times PySCF's cubegen.orbital for benzene B3LYP/6-31G* HOMO on an 80^3 grid, one thread.

The Rust side is `cargo bench --bench gto_grid` (same molecule, basis, grid box: the atoms plus
3 bohr, 80 points per axis). Prints `pyscf_s=<seconds>` (best of --repeat runs, cube file
written to a temporary directory, SCF excluded) and `pyscf_eval_s=<seconds>` (AO evaluation and
the MO product alone, no file).
"""
import os

os.environ["OMP_NUM_THREADS"] = "1"
os.environ["OPENBLAS_NUM_THREADS"] = "1"
os.environ["MKL_NUM_THREADS"] = "1"

import argparse  # noqa: E402
import tempfile  # noqa: E402
import time  # noqa: E402

import numpy as np  # noqa: E402
from pyscf import dft, gto, lib  # noqa: E402
from pyscf.tools import cubegen  # noqa: E402

BENZENE = """C 0.0000 1.3970 0.0000; C 1.2098 0.6985 0.0000; C 1.2098 -0.6985 0.0000;
C 0.0000 -1.3970 0.0000; C -1.2098 -0.6985 0.0000; C -1.2098 0.6985 0.0000;
H 0.0000 2.4810 0.0000; H 2.1486 1.2405 0.0000; H 2.1486 -1.2405 0.0000;
H 0.0000 -2.4810 0.0000; H -2.1486 -1.2405 0.0000; H -2.1486 1.2405 0.0000"""


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--n", type=int, default=80)
    ap.add_argument("--repeat", type=int, default=3)
    args = ap.parse_args()
    lib.num_threads(1)
    mol = gto.M(atom=BENZENE, basis="6-31g*", symmetry=False, verbose=0)
    mf = dft.RKS(mol)
    mf.xc = "b3lyp"
    mf.kernel()
    homo = int(np.max(np.nonzero(mf.mo_occ > 0)))
    c = mf.mo_coeff[:, homo]
    n = args.n
    best = best_eval = float("inf")
    with tempfile.TemporaryDirectory() as tmp:
        path = os.path.join(tmp, "homo.cube")
        for _ in range(args.repeat):
            t = time.perf_counter()
            cubegen.orbital(mol, path, c, nx=n, ny=n, nz=n)
            best = min(best, time.perf_counter() - t)
    cube = cubegen.Cube(mol, n, n, n)
    coords = cube.get_coords()
    for _ in range(args.repeat):
        t = time.perf_counter()
        ao = mol.eval_gto("GTOval", coords)
        _ = ao @ c
        best_eval = min(best_eval, time.perf_counter() - t)
    print(f"nao={mol.nao} grid={n}^3 threads={lib.num_threads()}")
    print(f"pyscf_s={best:.4f}")
    print(f"pyscf_eval_s={best_eval:.4f}")


if __name__ == "__main__":
    main()
