#!/usr/bin/env python3
"""Times PySCF's cubegen.orbital for an orbital on an 80^3 grid, one thread.

Molecules: benzene B3LYP/6-31G* (default) or the retinal-model cation PSB3,
H2C=CH-CH=CH-CH=NH2+ (RHF/6-31G*, planar). With --molden PATH the same SCF is also written as a
Molden file, so `orbcloud cube` can compute the same orbital on the same grid
(scripts/bench_cube_vs_pyscf.sh runs both and compares the cube files).

The Rust side is `cargo bench --bench gto_grid` (same molecule, basis, grid box: the atoms plus
3 bohr, 80 points per axis). Prints `pyscf_s=<seconds>` (best of --repeat runs, each cube
file new in a temporary directory, SCF excluded) and `pyscf_eval_s=<seconds>` (AO evaluation and
the MO product alone, no file).
"""
import os

os.environ.setdefault("OMP_NUM_THREADS", "1")
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
os.environ.setdefault("MKL_NUM_THREADS", "1")

import argparse  # noqa: E402
import shutil  # noqa: E402
import tempfile  # noqa: E402
import time  # noqa: E402

import numpy as np  # noqa: E402
from pyscf import dft, gto, lib, scf  # noqa: E402
from pyscf.tools import cubegen, molden  # noqa: E402

BENZENE = """C 0.0000 1.3970 0.0000; C 1.2098 0.6985 0.0000; C 1.2098 -0.6985 0.0000;
C 0.0000 -1.3970 0.0000; C -1.2098 -0.6985 0.0000; C -1.2098 0.6985 0.0000;
H 0.0000 2.4810 0.0000; H 2.1486 1.2405 0.0000; H 2.1486 -1.2405 0.0000;
H 0.0000 -2.4810 0.0000; H -2.1486 -1.2405 0.0000; H -2.1486 1.2405 0.0000"""


# PSB3 (Å), planar, all-trans: C1H2=C2H-C3H=C4H-C5H=N6H2+.
PSB3 = """C -3.0840 0.2360 0.0; H -3.1040 1.3210 0.0; H -4.0240 -0.3020 0.0;
C -1.9220 -0.4440 0.0; H -1.9440 -1.5300 0.0;
C -0.6290 0.1780 0.0; H -0.5740 1.2630 0.0;
C 0.5480 -0.5190 0.0; H 0.4910 -1.6030 0.0;
C 1.8300 0.0950 0.0; H 1.9310 1.1770 0.0;
N 2.9520 -0.5860 0.0; H 3.8580 -0.1350 0.0; H 2.9290 -1.5950 0.0"""


def arguments(n, molecule, threads=1):
    """The options both benchmarks take; PySCF limited to `threads` OpenMP threads."""
    ap = argparse.ArgumentParser()
    ap.add_argument("--n", type=int, default=n)
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--molecule", choices=["benzene", "psb3"], default=molecule)
    ap.add_argument("--molden", default=None, help="also write the SCF as a Molden file here")
    ap.add_argument("--cube", default=None, help="keep PySCF's cube file here")
    lib.num_threads(threads)
    return ap.parse_args()


def converged(molecule, molden_path=None):
    """The benchmark molecule's SCF (written as Molden when a path is given)."""
    if molecule == "benzene":
        mol = gto.M(atom=BENZENE, basis="6-31g*", symmetry=False, verbose=0)
        mf = dft.RKS(mol)
        mf.xc = "b3lyp"
    else:
        mol = gto.M(atom=PSB3, basis="6-31g*", charge=1, symmetry=False, verbose=0)
        mf = scf.RHF(mol)
    mf.kernel()
    if molden_path:
        molden.from_scf(mf, molden_path)
    return mol, mf


def main():
    args = arguments(80, "benzene")
    mol, mf = converged(args.molecule, args.molden)
    homo = int(np.max(np.nonzero(mf.mo_occ > 0)))
    c = mf.mo_coeff[:, homo]
    n = args.n
    best = best_eval = float("inf")
    with tempfile.TemporaryDirectory() as tmp:
        # A new file each time: truncating the file the previous run has just written waits
        # for the kernel to write it back, which is no part of either program's work.
        for i in range(args.repeat):
            path = os.path.join(tmp, f"homo{i}.cube")
            t = time.perf_counter()
            cubegen.orbital(mol, path, c, nx=n, ny=n, nz=n)
            best = min(best, time.perf_counter() - t)
        if args.cube:
            shutil.copy(path, args.cube)
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
