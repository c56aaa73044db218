"""NCI fixtures, made with PySCF: a hydrogen-bonded water dimer (HF/6-31G*, the donor's O–H
pointing at the acceptor's O, O···O 2.91 Å), written as

  tests/fixtures/nci/water_dimer_631gs.molden   PySCF's Molden writer

The viewer's NCI surface and plot tests open it: its hydrogen bond is the disc of low reduced
density gradient between the two molecules, at sign(λ₂)ρ ≈ −0.025 a.u. Run from the
repository root:
    python3 scripts/make_nci_fixtures.py        (pyscf, numpy; see requirements.txt)
"""

import os

from pyscf import gto, scf
from pyscf.tools import molden

OUT = os.path.join("tests", "fixtures", "nci")

# Near the experimental dimer geometry (Å): the donor in the xz plane, the acceptor's plane
# perpendicular.
DIMER = """
O  -1.551007  -0.114520   0.000000
H  -1.934259   0.762503   0.000000
H  -0.599677   0.040712   0.000000
O   1.350625   0.111469   0.000000
H   1.680398  -0.373741  -0.758561
H   1.680398  -0.373741   0.758561
"""


def main() -> None:
    os.makedirs(OUT, exist_ok=True)
    mol = gto.M(atom=DIMER, basis="6-31g*", unit="Angstrom", verbose=0)
    mf = scf.RHF(mol).run()
    assert mf.converged
    path = os.path.join(OUT, "water_dimer_631gs.molden")
    molden.from_scf(mf, path)
    print(path, mf.e_tot)


if __name__ == "__main__":
    main()
