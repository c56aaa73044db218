#!/usr/bin/env python3
"""Writes tests/fixtures/scan_fchk/: three frames of the bundled PSB3 scan (-120, -90, -60
degrees) as gzipped fchk files that also carry an optimisation history, the way per-point
files of a relaxed scan do (each a constrained optimisation with its own checkpoint).

For each angle it reads the geometry of assets/psb3/psb3_mXXX.molden.gz, runs the same
RHF/6-31G* single point as scripts/make_psb3_scan.py (its build_mol and run_rhf), and writes
psb3_mXXX.fchk.gz with scripts/make_wavefunction_fixtures.py's fchk writer (Gaussian
conventions), keeping the 22 occupied orbitals and the 4 lowest virtual ones. Two records
follow, as Gaussian writes them for an optimisation: "Opt point 1 Geometries" with two
frames (the geometry with the moving fragment 10 degrees short of the target, then the final
one, identical to "Current cartesian coordinates") and "Opt point 1 Results for each geome"
(energy and a gradient-norm placeholder per frame). The current geometry is the one the
orbitals belong to, and the one a reader must use.

Run:   OMP_NUM_THREADS=1 python3 scripts/make_scan_fchk_fixtures.py
       (PySCF, numpy, geomeTRIC as for make_psb3_scan.py; about half a minute.)
"""
import gzip
import os
import sys
import tempfile
from pathlib import Path

import numpy as np
from pyscf.tools import molden

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))
import make_psb3_scan as psb3  # noqa: E402
import make_wavefunction_fixtures as fx  # noqa: E402

ASSETS = HERE.parent / "assets" / "psb3"
OUT = HERE.parent / "tests" / "fixtures" / "scan_fchk"
ANGLES = [-120, -90, -60]
VIRTUALS = 4
BOHR = 0.52917721090380


def main() -> None:
    OUT.mkdir(parents=True, exist_ok=True)
    for angle in ANGLES:
        stem = psb3.stem(angle)
        with tempfile.NamedTemporaryFile("wb", suffix=".molden") as tmp:
            tmp.write(gzip.decompress((ASSETS / (stem + ".molden.gz")).read_bytes()))
            tmp.flush()
            mol0, *_ = molden.load(tmp.name)
        xyz = mol0.atom_coords(unit="Bohr") * BOHR
        mol = psb3.build_mol(xyz)
        mf = psb3.run_rhf(mol)
        keep = mol.nelectron // 2 + VIRTUALS
        path = OUT / (stem + ".fchk")
        fx.write_fchk(str(path), "PSB3 %d deg, constrained optimisation" % angle, "RHF", psb3.BASIS, mol, mf, keep)
        # The optimisation history: a start 10 degrees short of the target, then the end.
        start = xyz.copy()
        moving = [3, 4, 5, 10, 11, 12, 13]  # C4's side of C3=C4: C4, C5, N, H4, H5, HNa, HNb
        start[moving] = psb3.rotate_about(xyz[moving], xyz[3], xyz[3] - xyz[2], -10.0)
        f = fx.Fchk()
        frames = np.concatenate([start, xyz]) / BOHR
        f.reals("Opt point       1 Results for each geome", [mf.e_tot + 0.001, 0.01, mf.e_tot, 0.0])
        f.reals("Opt point       1 Geometries", frames)
        with open(path, "a") as out:
            out.write("\n".join(f.lines) + "\n")
        with open(path, "rb") as src, gzip.GzipFile(str(path) + ".gz", "wb", 9, mtime=0) as dst:
            dst.write(src.read())
        os.remove(path)
        print("%s.fchk.gz: E = %.10f, HOMO %.6f, LUMO %.6f, %d orbitals" % (
            stem, mf.e_tot, mf.mo_energy[keep - VIRTUALS - 1], mf.mo_energy[keep - VIRTUALS], keep))


if __name__ == "__main__":
    main()
