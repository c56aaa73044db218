#!/usr/bin/env python3
"""Writes tests/fixtures/wavefunctions/h2_spdfgh.molden: RHF orbitals of H2 in a small custom
basis with pure d, f, g and h (l = 5) functions on the first atom, as a Molden file.

PySCF's Molden writer refuses l = 5, so its pure-function ordering is extended here the way the
Molden convention continues for h: m = 0, +1, -1, +2, -2, ..., +5, -5 (PySCF orders m = -l..+l).
Everything else is pyscf.tools.molden as is ([5d] [7f] [9g] tags; h is pure like g).

Run:   python scripts/make_h_molden_fixture.py      (PySCF 2.x)
"""
import os

from pyscf import gto, scf
from pyscf.tools import molden

OUT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "tests", "fixtures", "wavefunctions",
                   "h2_spdfgh.molden")

# One primitive per polarisation shell keeps the file small (42 functions, 42 orbitals).
BASIS = {
    "H1": [[0, (3.0, 0.4), (0.6, 0.7)], [0, (0.2, 1.0)], [1, (1.1, 1.0)], [2, (1.0, 1.0)],
           [3, (0.9, 1.0)], [4, (0.8, 1.0)], [5, (0.7, 1.0)]],
    "H2": [[0, (3.0, 0.4), (0.6, 0.7)], [0, (0.2, 1.0)], [1, (1.1, 1.0)]],
}


def order_ao_index(mol):
    """pyscf.tools.molden.order_ao_index for pure shells of any l (this fixture has no cartesian)."""
    assert not mol.cart
    idx, off = [], 0
    for ib in range(mol.nbas):
        l = mol.bas_angular(ib)
        for _ in range(mol.bas_nctr(ib)):
            # p stays x, y, z (PySCF's order for l = 1, and Molden's).
            order = range(3) if l == 1 else [l] + [l + s * m for m in range(1, l + 1) for s in (1, -1)]
            idx.extend(off + k for k in order)
            off += 2 * l + 1
    return idx


def main():
    mol = gto.M(atom="H1 0 0 0; H2 0 0 0.74", basis=BASIS, unit="Angstrom", symmetry=False, verbose=0)
    mf = scf.RHF(mol).run(conv_tol=1e-12)
    molden.order_ao_index = order_ao_index
    with open(OUT, "w") as f:
        molden.header(mol, f, ignore_h=False)
        molden.orbital_coeff(mol, f, mf.mo_coeff, ene=mf.mo_energy, occ=mf.mo_occ, ignore_h=False)
    print(f"{OUT}: {mol.nao} functions, E = {mf.e_tot:.10f}")


if __name__ == "__main__":
    main()
