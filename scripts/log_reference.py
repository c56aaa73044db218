#!/usr/bin/env python3
"""Reference densities for the Hartree–Fock program logs of divinylbenzene, computed without
orbcloud: the geometry is read here from each log's own table, PySCF runs RHF/STO-3G on it and
evaluates the density at a set of points.

    target/pyenv/bin/python scripts/log_reference.py ../shared/refdata/real-world/logs \
        > tests/fixtures/logs/hf_log_reference.json

For each log (NWChem 6.5 RHF; Psi4 1.3.1 DF-RHF, run here with density fitting in the same
auxiliary basis, def2-universal-jkfit = def2-SVP-JKFIT): the points (bohr, in the log's own
orientation: each nucleus and 40 points around them, the same recipe as tests/refdata_logs.rs),
the density there, the total energy and the HOMO and LUMO energies (hartree). The GAMESS, ORCA
and Q-Chem single points are B3LYP and are not recomputed (their quadrature grids differ):
their test compares the orbital energies the log prints and the electron count instead.
"""
import json
import math
import os
import sys

import numpy as np
from pyscf import df, gto, lib, scf

ANGSTROM = 1.0 / 0.529177210903  # bohr per ångström (CODATA 2018, as orbcloud)


def nwchem_geometry(lines):
    """The last `Output coordinates in angstroms` table: `No. Tag Charge X Y Z`."""
    start = max(i for i, l in enumerate(lines) if "Output coordinates in angstroms" in l)
    atoms = []
    for l in lines[start + 4:]:
        t = l.split()
        if len(t) != 6:
            break
        atoms.append((t[1], [float(v) * ANGSTROM for v in t[3:6]]))
    return atoms


def psi4_geometry(lines):
    """The last `Geometry (in Angstrom)` table: `Center X Y Z Mass`."""
    start = max(i for i, l in enumerate(lines) if "Geometry (in Angstrom)" in l)
    atoms = []
    for l in lines[start + 4:]:
        t = l.split()
        if len(t) != 5:
            break
        atoms.append((t[0], [float(v) * ANGSTROM for v in t[1:4]]))
    return atoms


def points(positions):
    """Each nucleus, then 40 points around them (bohr), as tests/refdata_logs.rs makes them."""
    out = [list(p) for p in positions]
    n = len(positions)
    for k in range(40):
        a = positions[(k * 7) % n]
        d = [math.sin(k * 1.1), math.cos(k * 0.7), 0.3 * ((k % 5) - 2.0)]
        out.append([a[i] + 0.9 * d[i] for i in range(3)])
    return out


def run(atoms, density_fit):
    mol = gto.M(
        atom=[(s, p) for s, p in atoms], unit="Bohr", basis="sto-3g", cart=False, symmetry=False, verbose=0
    )
    mf = scf.RHF(mol)
    if density_fit:
        mf = mf.density_fit(auxbasis="def2-universal-jkfit")
    mf.conv_tol = 1e-11
    mf.conv_tol_grad = 1e-7
    mf.kernel()
    assert mf.converged
    at = np.array(points([p for _, p in atoms]))
    ao = mol.eval_gto("GTOval_sph", at)
    rho = np.einsum("pi,ij,pj->p", ao, mf.make_rdm1(), ao)
    nocc = mol.nelectron // 2
    return {
        "points_bohr": at.tolist(),
        "density": rho.tolist(),
        "energy": float(mf.e_tot),
        "homo": float(mf.mo_energy[nocc - 1]),
        "lumo": float(mf.mo_energy[nocc]),
        "method": "RHF/STO-3G" + (" (density fitting, def2-universal-jkfit)" if density_fit else ""),
    }


def main():
    lib.num_threads(2)
    folder = sys.argv[1]
    out = {}
    for name, geometry, density_fit in [
        ("basicNWChem6.5_dvb_sp_hf.out", nwchem_geometry, False),
        ("basicPsi4-1.3.1_dvb_sp_rhf.out", psi4_geometry, True),
    ]:
        with open(os.path.join(folder, name)) as f:
            lines = f.read().splitlines()
        out[name] = run(geometry(lines), density_fit)
        print(f"{name}: E = {out[name]['energy']:.8f}", file=sys.stderr)
    json.dump(out, sys.stdout, indent=1)
    print()


if __name__ == "__main__":
    main()
