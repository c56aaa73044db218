#!/usr/bin/env python3
"""Times PySCF's cubegen.mep (the electrostatic potential on a cube grid), two threads.

Molecules as scripts/bench_cube_vs_pyscf.py: PSB3 (RHF/6-31G*, 14 atoms, default) or benzene
(B3LYP/6-31G*). With --molden PATH the same SCF is also written as a Molden file, so
`orbcloud cube --esp` computes the same potential on the same grid (scripts/bench_esp_vs_pyscf.sh
runs both and compares the cube files). Prints `pyscf_s=<seconds>` (best of --repeat runs,
SCF excluded). Two threads, as orbcloud gets: OpenMP for the integrals (PySCF's `aux_e2`) and
BLAS for their contraction with the density matrix.
"""
import os

THREADS = 2
os.environ["OMP_NUM_THREADS"] = str(THREADS)
os.environ["OPENBLAS_NUM_THREADS"] = str(THREADS)
os.environ["MKL_NUM_THREADS"] = str(THREADS)

import shutil  # noqa: E402
import sys  # noqa: E402
import tempfile  # noqa: E402
import time  # noqa: E402

from pyscf import lib  # noqa: E402
from pyscf.tools import cubegen  # noqa: E402

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from bench_cube_vs_pyscf import arguments, converged  # noqa: E402


def main():
    args = arguments(40, "psb3", THREADS)
    mol, mf = converged(args.molecule, args.molden)
    dm = mf.make_rdm1()
    n = args.n
    best = float("inf")
    with tempfile.TemporaryDirectory() as tmp:
        for i in range(args.repeat):
            path = os.path.join(tmp, f"mep{i}.cube")  # a new file each time, as orbcloud's
            t = time.perf_counter()
            cubegen.mep(mol, path, dm, nx=n, ny=n, nz=n)
            best = min(best, time.perf_counter() - t)
        if args.cube:
            shutil.copy(path, args.cube)
    print(f"atoms={mol.natm} nao={mol.nao} grid={n}^3 threads={lib.num_threads()}")
    print(f"pyscf_s={best:.4f}")


if __name__ == "__main__":
    main()
