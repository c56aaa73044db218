"""NCI fixtures, made with PySCF: a hydrogen-bonded water dimer (HF/6-31G*, the donor's O–H
pointing at the acceptor's O, O···O 2.91 Å), written as

  tests/fixtures/nci/water_dimer_631gs.molden   PySCF's Molden writer
  tests/fixtures/nci/water_dimer.pdb            the same atoms as a structure of two residues,
                                                the donor HOH 1 and the acceptor LIG 2
  tests/fixtures/nci/water_donor_631gs.molden   each water alone at its place in the dimer
  tests/fixtures/nci/water_acceptor_631gs.molden  (HF/6-31G*): fragments whose densities add

The viewer's NCI surface and plot tests open the Molden file; the structure's spherical atoms
give the promolecular NCI between `resn LIG` and the rest. The viewer's tests open it: its hydrogen bond is the disc of low reduced
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


def write_pdb(path: str) -> None:
    """The dimer as PDB HETATM records: the donor (first three atoms) residue HOH 1, the
    acceptor LIG 2, chain A, with element columns."""
    lines = []
    for n, line in enumerate(DIMER.strip().splitlines()):
        element, x, y, z = line.split()
        resn, resi = ("HOH", 1) if n < 3 else ("LIG", 2)
        name = f"{element}{n % 3 if element == 'H' else ''}"
        lines.append(
            f"HETATM{n + 1:5d} {name:<4s} {resn} A{resi:4d}    {float(x):8.3f}{float(y):8.3f}{float(z):8.3f}"
            f"  1.00  0.00          {element:>2s}"
        )
    with open(path, "w") as f:
        f.write("\n".join(lines + ["END", ""]))


def main() -> None:
    os.makedirs(OUT, exist_ok=True)
    write_pdb(os.path.join(OUT, "water_dimer.pdb"))
    mol = gto.M(atom=DIMER, basis="6-31g*", unit="Angstrom", verbose=0)
    mf = scf.RHF(mol).run()
    assert mf.converged
    path = os.path.join(OUT, "water_dimer_631gs.molden")
    molden.from_scf(mf, path)
    print(path, mf.e_tot)
    lines = DIMER.strip().splitlines()
    for name, atoms in [("donor", lines[:3]), ("acceptor", lines[3:])]:
        monomer = gto.M(atom="\n".join(atoms), basis="6-31g*", unit="Angstrom", verbose=0)
        mf = scf.RHF(monomer).run()
        assert mf.converged
        path = os.path.join(OUT, f"water_{name}_631gs.molden")
        molden.from_scf(mf, path)
        print(path, mf.e_tot)


if __name__ == "__main__":
    main()
