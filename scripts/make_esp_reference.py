#!/usr/bin/env python3
"""Writes tests/fixtures/esp/real_world_esp.tsv: the electrostatic potential of the Molden and
fchk files of the shared real-world corpus (../shared/refdata/real-world, written by ORCA, CFOUR,
Gaussian, Psi4, Turbomole, Molpro, Molden and Q-Chem) at random points, computed by a chain
independent of orbcloud and of PySCF: IOData reads each file (and repairs each writer's
normalisation), GBasis integrates.

V(C) = sum_A Z_A / |C - R_A| - sum_ab P_ab (a|1/r_C|b), with Z_A IOData's `atcorenums` (core
charges: ghost atoms count 0) and P the total (alpha + beta) density matrix of the file's
orbitals and occupations, P = C diag(occ) C^T. Points: 40 per file (seed 11), each within 0.3 to
4 bohr of a randomly chosen atom and never closer than 0.3 bohr to any nucleus.

Every value is checked against a second route on the files PySCF reads correctly (Molpro's and
Molden's own, pure and cartesian functions): PySCF's `int1e_rinv` per point with the density
matrix from PySCF's Molden reader.

Columns: file, x, y, z (bohr), value (a.u.), full precision. The corpus itself is not copied.

Run: python3 scripts/make_esp_reference.py   (qc-iodata 1.0.1, qc-gbasis 1.0.0, pyscf 2.x)
"""
import os
import sys
import warnings

import numpy as np
from gbasis.evals.electrostatic_potential import electrostatic_potential
from gbasis.wrappers import from_iodata
from iodata import load_one

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.join(HERE, "..")
CORPUS = os.environ.get("ORBCLOUD_REFDATA", os.path.join(ROOT, "..", "shared", "refdata", "real-world"))
OUT = os.path.join(ROOT, "tests", "fixtures", "esp", "real_world_esp.tsv")

FILES = [
    "nh3_orca.molden",  # ORCA
    "h2o_ccpvdz_cfour.molden",  # CFOUR
    "o2_cc_pvtz_cart.fchk",  # Gaussian
    "water_dimer_ghost.fchk",  # Gaussian, ghost atoms
    "water_hf_sto3g_qchem5.2.fchk",  # Q-Chem
    "h2o_psi4_1.3.2_6-31G_d_cart.molden",  # Psi4
    "he2_ghost_psi4_1.0.molden",  # Psi4, a ghost atom
    "nh3_turbomole.molden",  # Turbomole
    "nh3_molpro2012.molden",  # Molpro
    "nh3_molden_pure.molden",  # Molden
]
# Files PySCF's Molden reader reads correctly (no writer repair needed): the second route.
PYSCF_CHECK = ["nh3_molpro2012.molden", "nh3_molden_pure.molden"]

N_POINTS = 40
SEED = 11
NEAREST = 0.3
FARTHEST = 4.0


def points_near(atcoords, rng):
    out = []
    while len(out) < N_POINTS:
        centre = atcoords[rng.integers(len(atcoords))]
        u = rng.normal(size=3)
        p = centre + u / np.linalg.norm(u) * rng.uniform(NEAREST, FARTHEST)
        if np.linalg.norm(atcoords - p, axis=1).min() >= NEAREST:
            out.append(p)
    return np.array(out)


def iodata_gbasis(path, points):
    with warnings.catch_warnings():
        # IOData says which writer repair it applied; the repair is wanted.
        warnings.simplefilter("ignore")
        mol = load_one(path)
    c = mol.mo.coeffs
    dm = (c * mol.mo.occs) @ c.T
    basis = from_iodata(mol)
    v = electrostatic_potential(basis, dm, points, mol.atcoords, np.asarray(mol.atcorenums, dtype=float))
    return mol, v


def pyscf_route(path, points):
    from pyscf.tools import molden

    mol, _, mo_coeff, mo_occ, _, _ = molden.load(path)
    dm = (mo_coeff * mo_occ) @ mo_coeff.T
    charges, coords = mol.atom_charges(), mol.atom_coords(unit="Bohr")
    out = []
    for c in points:
        with mol.with_rinv_origin(c):
            rinv = mol.intor("int1e_rinv")
        out.append(sum(q / np.linalg.norm(c - r) for q, r in zip(charges, coords)) - np.einsum("ij,ij", dm, rinv))
    return np.array(out)


def main():
    if not os.path.isdir(CORPUS):
        sys.exit(f"the corpus {CORPUS} is absent (set ORBCLOUD_REFDATA)")
    rng = np.random.default_rng(SEED)
    lines = ["# file\tx\ty\tz\tesp  (bohr, a.u.; IOData + GBasis; scripts/make_esp_reference.py)"]
    for name in FILES:
        path = os.path.join(CORPUS, name)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            atcoords = load_one(path).atcoords
        points = points_near(atcoords, rng)
        mol, v = iodata_gbasis(path, points)
        note = ""
        if name in PYSCF_CHECK:
            diff = np.abs(pyscf_route(path, points) - v).max()
            assert diff < 1e-8, f"{name}: PySCF and GBasis differ by {diff:.1e}"
            note = f", PySCF agrees to {diff:.1e}"
        print(f"{name}: {len(v)} points, V in [{v.min():.4f}, {v.max():.4f}]{note}")
        for p, x in zip(points, v):
            lines.append("\t".join([name] + [repr(float(t)) for t in p] + [repr(float(x))]))
    with open(OUT, "w") as f:
        f.write("\n".join(lines) + "\n")
    print(f"wrote {OUT}: {len(lines) - 1} points")


if __name__ == "__main__":
    main()
