#!/usr/bin/env python3
"""Writes tests/fixtures/esp/*.json: the electrostatic potential from PySCF at points around the
molecules of the wavefunction fixtures, and one fchk file with a pseudopotential (HI, def2-SVP:
iodine's 28 core electrons replaced, nuclear charge 25).

The potential is computed by PySCF alone: the wavefunction comes from PySCF's own Molden reader
(or, for the h-function fixture whose ordering PySCF's reader does not know, from the same
converged RHF the fixture was written from: the density matrix of a converged RHF does not depend
on the orbitals' phases), V(C) = Σ_A Z_A/|C − R_A| − Σ_μν P_μν (μ|1/r_C|ν) with `int1e_rinv` per
point and the charges of `mol.atom_charges()` (core charges with pseudopotentials).

It also writes a density cube and a potential cube of water (cc-pVTZ) with PySCF's cubegen on
two different grids (`h2o_density.cube`, `h2o_potential.cube`): the pair a viewer opens together.
`--pair-only DIR N` writes just that pair on N³ and (N·3/4)³ points into DIR (for screenshots).

Run: python scripts/make_esp_fixtures.py   (PySCF 2.x; output is deterministic)
"""
import json
import os
import sys

import numpy as np
from pyscf import gto, scf
from pyscf.tools import cubegen, molden

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.join(HERE, "..")
WAVEFUNCTIONS = os.path.join(ROOT, "tests", "fixtures", "wavefunctions")
OUT = os.path.join(ROOT, "tests", "fixtures", "esp")
N_POINTS = 40
PAD = 4.0
SEED = 26

sys.path.insert(0, HERE)
import make_h_molden_fixture  # noqa: E402
import make_wavefunction_fixtures  # noqa: E402


def points_around(mol, rng):
    """Random points in the molecule's box plus 4 bohr, and a few within 0.3 bohr of nuclei."""
    xyz = mol.atom_coords(unit="Bohr")
    lo, hi = xyz.min(0) - PAD, xyz.max(0) + PAD
    pts = lo + (hi - lo) * rng.random((N_POINTS, 3))
    near = xyz[rng.integers(0, len(xyz), 4)] + rng.normal(scale=0.15, size=(4, 3))
    return np.vstack([pts, near])


def esp(mol, dm, points):
    charges = mol.atom_charges()
    coords = mol.atom_coords(unit="Bohr")
    out = []
    for c in points:
        nuclear = sum(q / np.linalg.norm(c - r) for q, r in zip(charges, coords))
        with mol.with_rinv_origin(c):
            v = mol.intor("int1e_rinv")
        out.append(nuclear - np.einsum("ij,ij", dm, v))
    return out


def density_matrix(mo_coeff, mo_occ):
    c, occ = np.asarray(mo_coeff), np.asarray(mo_occ)
    if c.ndim == 3:
        return sum(ci @ np.diag(oi) @ ci.T for ci, oi in zip(c, occ))
    return c @ np.diag(occ) @ c.T


def write(name, source, mol, dm, rng):
    points = points_around(mol, rng)
    values = esp(mol, dm, points)
    ref = {
        "source": source,
        "charge": int(mol.charge),
        "points": points.tolist(),
        "esp": [float(v) for v in values],
    }
    with open(os.path.join(OUT, name + ".json"), "w") as f:
        json.dump(ref, f, indent=1)
    print(f"{name}: {len(values)} points, nao {mol.nao}, ESP range {min(values):.4f} .. {max(values):.4f}")


def cube_pair(out, n):
    """cubegen's density on n³ points and its potential on (3n/4)³ points with a wider margin:
    two files of the same atoms on grids that differ, as two runs of cubegen write them."""
    mol, _, mo_coeff, mo_occ, _, _ = molden.load(os.path.join(WAVEFUNCTIONS, "h2o_ccpvtz.molden"))
    dm = density_matrix(mo_coeff, mo_occ)
    m = n * 3 // 4
    for name, write, points, margin in [("h2o_density.cube", cubegen.density, n, 4.5),
                                        ("h2o_potential.cube", cubegen.mep, m, 5.0)]:
        path = os.path.join(out, name)
        write(mol, path, dm, nx=points, ny=points, nz=points, margin=margin)
        # The date PySCF stamps on line 2 would make every run's file differ.
        with open(path) as f:
            lines = f.read().split("\n")
        lines[1] = lines[1].split("Date:")[0].rstrip()
        with open(path, "w") as f:
            f.write("\n".join(lines))
    print(f"h2o_density.cube ({n}³), h2o_potential.cube ({m}³) in {out}")


def main():
    if len(sys.argv) == 4 and sys.argv[1] == "--pair-only":
        os.makedirs(sys.argv[2], exist_ok=True)
        cube_pair(sys.argv[2], int(sys.argv[3]))
        return
    os.makedirs(OUT, exist_ok=True)
    cube_pair(OUT, 16)
    rng = np.random.default_rng(SEED)
    for name in ["h2o_cart_631gs", "h2o_ccpvtz", "h2o_cation_uhf_631gs", "h3o_cation_631gss", "benzene_631gs"]:
        mol, _, mo_coeff, mo_occ, _, _ = molden.load(os.path.join(WAVEFUNCTIONS, name + ".molden"))
        mol.charge = int(round(sum(mol.atom_charges()) - np.sum(mo_occ)))
        write(name, f"wavefunctions/{name}.molden", mol, density_matrix(mo_coeff, mo_occ), rng)

    # d, f, g and h functions.
    mol = gto.M(atom="H1 0 0 0; H2 0 0 0.74", basis=make_h_molden_fixture.BASIS, unit="Angstrom",
                symmetry=False, verbose=0)
    mf = scf.RHF(mol).run(conv_tol=1e-12)
    write("h2_spdfgh", "wavefunctions/h2_spdfgh.molden", mol, mf.make_rdm1(), rng)

    # Volume arithmetic: water's density in cc-pVTZ minus the same in cartesian 6-31G*, both
    # from PySCF's reading of the Molden files.
    def density(name, points):
        mol, _, mo_coeff, mo_occ, _, _ = molden.load(os.path.join(WAVEFUNCTIONS, name + ".molden"))
        ao = mol.eval_gto("GTOval_cart" if mol.cart else "GTOval_sph", points)
        return np.einsum("pi,ij,pj->p", ao, density_matrix(mo_coeff, mo_occ), ao)

    points = points_around(gto.M(atom=make_wavefunction_fixtures.H2O, unit="Angstrom", verbose=0), rng)
    diff = density("h2o_ccpvtz", points) - density("h2o_cart_631gs", points)
    with open(os.path.join(OUT, "density_difference.json"), "w") as f:
        json.dump({"a": "wavefunctions/h2o_ccpvtz.molden", "b": "wavefunctions/h2o_cart_631gs.molden",
                   "points": points.tolist(), "difference": diff.tolist()}, f, indent=1)
    print(f"density_difference: {len(diff)} points, |Δρ| up to {np.abs(diff).max():.4f}")

    # A pseudopotential: the nuclear term uses the core charge the fchk file gives.
    mol = gto.M(atom="H 0 0 0; I 0 0 1.61", basis="def2-svp", ecp="def2-svp", unit="Angstrom",
                symmetry=False, verbose=0)
    mf = scf.RHF(mol).run(conv_tol=1e-11)
    assert mf.converged
    path = os.path.join(OUT, "hi_def2svp_ecp.fchk")
    make_wavefunction_fixtures.write_fchk(path, "HI def2-SVP with ECP", "RHF", "def2SVP", mol, mf, mol.nao)
    write("hi_def2svp_ecp", "esp/hi_def2svp_ecp.fchk", mol, mf.make_rdm1(), rng)


if __name__ == "__main__":
    main()
