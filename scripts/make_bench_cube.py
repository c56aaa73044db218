#!/usr/bin/env python3
"""Write the benchmark volume: the benzene HOMO, B3LYP/6-31G*, on an 80x80x80 grid.

    python3 scripts/make_bench_cube.py [OUT] [--size N] [--orbital homo|lumo|...]

OUT defaults to target/bench/benzene_homo_80.cube (not part of the
repository; regenerate it before running benchmarks). Benzene is planar in
xy, centred at the origin, r(CC) 1.397 Å, r(CH) 1.084 Å; symmetry off.
The grid has PySCF cubegen's default 3.0 bohr margin.

The benzene HOMO is a degenerate e1g pair; which member (or mixture) the
SCF returns is fixed for a given PySCF/BLAS build but is not a symmetry
choice, so benchmarks should not depend on its exact shape.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from make_assets import build_mol, describe, run_scf, write_orbital_cube  # noqa: E402

R_CC = 1.397
R_CH = 1.084


def benzene():
    atoms = []
    for k in range(6):
        a = np.deg2rad(60.0 * k)
        atoms.append(("C", (R_CC * np.cos(a), R_CC * np.sin(a), 0.0)))
    for k in range(6):
        a = np.deg2rad(60.0 * k)
        r = R_CC + R_CH
        atoms.append(("H", (r * np.cos(a), r * np.sin(a), 0.0)))
    return atoms


def main(argv: list[str] | None = None) -> int:
    repo = Path(__file__).resolve().parent.parent
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("out", nargs="?", default=str(repo / "target" / "bench" / "benzene_homo_80.cube"))
    ap.add_argument("--size", type=int, default=80, help="points per axis (default 80)")
    ap.add_argument("--orbital", default="homo")
    ap.add_argument("--margin", type=float, default=3.0, help="bohr (default 3.0)")
    args = ap.parse_args(argv)

    t0 = time.perf_counter()
    mol = build_mol(benzene(), basis="6-31g*")
    mf = run_scf(mol, "b3lyp")
    t1 = time.perf_counter()
    print(f"C6H6 B3LYP/6-31G*: E = {mf.e_tot:.8f} Eh, {mol.nao_nr()} AOs, SCF {t1 - t0:.1f} s")
    info = write_orbital_cube(mol, mf, args.out, which=args.orbital, n=args.size,
                              margin=args.margin, gzip_level=9 if args.out.endswith(".gz") else None)
    t2 = time.perf_counter()
    print(describe(info, args.out))
    print(f"cube written in {t2 - t1:.2f} s")
    return 0


if __name__ == "__main__":
    sys.exit(main())
