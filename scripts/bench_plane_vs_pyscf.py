#!/usr/bin/env python3
"""`orbcloud plane` against PySCF evaluating the same plane's points, one thread each.

The SCF of scripts/bench_cube_vs_pyscf.py (benzene B3LYP/6-31G* or the PSB3 cation RHF/6-31G*)
is written as Molden. orbcloud is timed as the whole process (reading the file, checking CᵀSC,
evaluating the HOMO at N×N points of the plane 1 bohr above the first three atoms, contouring,
drawing and writing the PNG; best of --repeat); a separate run writes the points and values as
CSV. PySCF is timed evaluating those same points alone (`eval_ao` and the product with the
HOMO's coefficients; best of --repeat), and the two sets of values are compared.
   bench_plane_vs_pyscf.py --molecule benzene --n 500 --out target/bench
"""
import os

os.environ["OMP_NUM_THREADS"] = "1"
os.environ["OPENBLAS_NUM_THREADS"] = "1"
os.environ["MKL_NUM_THREADS"] = "1"

import argparse  # noqa: E402
import subprocess  # noqa: E402
import sys  # noqa: E402
import time  # noqa: E402

import numpy as np  # noqa: E402
from pyscf import lib  # noqa: E402

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from bench_cube_vs_pyscf import converged  # noqa: E402


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--molecule", choices=["benzene", "psb3"], default="benzene")
    ap.add_argument("--n", type=int, default=500)
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--out", default="target/bench")
    args = ap.parse_args()
    lib.num_threads(1)
    os.makedirs(args.out, exist_ok=True)
    molden = os.path.join(args.out, f"{args.molecule}.molden")
    mol, mf = converged(args.molecule, molden)
    homo = int(np.max(np.nonzero(mf.mo_occ > 0)))

    plane = ["target/release/orbcloud", "plane", molden, "--orbital", "homo", "--through", "1,2,3",
             "--offset", "0.529177", "--points", str(args.n)]
    png = os.path.join(args.out, f"{args.molecule}_plane.png")
    csv = os.path.join(args.out, f"{args.molecule}_plane.csv")
    one_thread = {**os.environ, "RAYON_NUM_THREADS": "1"}
    ours = float("inf")
    for _ in range(args.repeat):
        t = time.perf_counter()
        subprocess.run([*plane, "-o", png], check=True, stderr=subprocess.DEVNULL, env=one_thread)
        ours = min(ours, time.perf_counter() - t)
    t = time.perf_counter()
    subprocess.run([*plane, "-o", png, "--values", csv], check=True, stderr=subprocess.DEVNULL, env=one_thread)
    with_csv = time.perf_counter() - t

    table = np.loadtxt(csv, delimiter=",", skiprows=1)
    points = np.ascontiguousarray(table[:, :3])
    c = mf.mo_coeff[:, homo]
    theirs = float("inf")
    for _ in range(args.repeat):
        t = time.perf_counter()
        ref = mol.eval_gto("GTOval_sph", points) @ c
        theirs = min(theirs, time.perf_counter() - t)
    diff = np.abs(table[:, 3] - ref).max()
    print(f"{args.molecule} HOMO, {args.n}x{args.n} points 1 bohr above atoms 1,2,3; {mol.nao} AOs")
    print(f"max |orbcloud - PySCF| = {diff:.1e}, relative to max |psi| {diff / np.abs(ref).max():.1e}")
    print(f"orbcloud plane (whole process, PNG) {ours:.3f} s; with the CSV written too {with_csv:.3f} s")
    print(f"pyscf_eval_s={theirs:.3f} orbcloud_s={ours:.3f} ratio={theirs / ours:.1f}")


if __name__ == "__main__":
    main()
