#!/usr/bin/env python3
"""An NWChem output of water RHF/cc-pVDZ in a spherical basis (pure d on oxygen), computed with
PySCF, with PySCF's orbital values at points beside it.

    target/pyenv/bin/python scripts/make_nwchem_spherical_fixture.py tests/fixtures/logs

writes `h2o_nwchem_ccpvdz.out` and `h2o_nwchem_ccpvdz.expected.json` (points in bohr and every
orbital's value there, as PySCF evaluates them).

The layout is that of NWChem 7.0's `C_bigbasis_spherical.out` (aug-cc-pCVQZ carbon) in cclib's
regression data, github.com/cclib/cclib at commit 21daa960123d28aa21eeaaacc2a1dea39e136829,
data/NWChem/basicNWChem7.0/: `Output coordinates in angstroms`, `Basis "ao basis" -> "ao basis"
(spherical)` (each contraction of a general contraction its own numbered shell, one primitive a
line), `closed shells`, `Total SCF energy`, the `ROHF Final Molecular Orbital Analysis` (`Vector n
Occ=… E=…`) and `Final MO vectors` (6 columns of F12.5, rows numbered only; p as x, y, z, pure
functions m = −l … +l).

NWChem's pure functions carry the Condon–Shortley phase: its m = +1 and +3 functions are the
negatives of the real solid harmonics PySCF and orbcloud use (d+1 = −xz, f+1, f+3 and g+1, g+3
likewise). That file shows it: its RHF carbon has one doubly occupied p orbital, so every orbital
is symmetric about that orbital's axis n; the coefficients of each d, f and g shell are then
proportional to the harmonics' values at n, and they are, to the printed precision, once the
m = +1 and +3 ones change sign (without: the orbitals lose that symmetry by up to 2% of their
largest value). So the coefficients written here are PySCF's with those signs changed.
"""
import json
import os
import sys

import numpy as np
from pyscf import gto, scf

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from make_log_mode_fixtures import nwchem_header  # noqa: E402  (the same banner and table)

ANGSTROM = 1.0 / 0.529177210903
LETTER = "SPDFGH"


def main():
    out_dir = sys.argv[1] if len(sys.argv) > 1 else "tests/fixtures/logs"
    mol = gto.M(
        atom="O 0 0 0.1173; H 0 0.7572 -0.4692; H 0 -0.7572 -0.4692",
        basis="cc-pvdz",
        unit="Angstrom",
        cart=False,
        verbose=0,
    )
    mf = scf.RHF(mol)
    mf.conv_tol = 1e-12
    mf.kernel()

    # NWChem's sign of each AO (PySCF's order is NWChem's: shells in order, m = −l … +l, p x y z).
    signs = []
    for ib in range(mol.nbas):
        l = mol.bas_angular(ib)
        for _ in range(mol.bas_nctr(ib)):
            for k in range(2 * l + 1):
                m = k - l
                signs.append(-1.0 if l >= 2 and m > 0 and m % 2 == 1 else 1.0)
    signs = np.array(signs)
    assert len(signs) == mol.nao
    coefficients = mf.mo_coeff * signs[:, None]

    lines = nwchem_header(mol)
    w = lines.append
    w("")
    w('                      Basis "ao basis" -> "ao basis" (spherical)')
    w("                      -----")
    names = {"O": "Oxygen", "H": "Hydrogen"}
    for symbol in ("O", "H"):
        w(f"  {symbol} ({names[symbol]})")
        w("  " + "-" * (len(names[symbol]) + 4))
        w("            Exponent  Coefficients ")
        w("       -------------- ---------------------------------------------------------")
        number = 0
        for shell in mol._basis[symbol]:
            l, primitives = shell[0], shell[1:]
            for c in range(1, len(primitives[0])):
                number += 1
                for p in primitives:
                    if p[c] != 0.0:
                        w(f"{number:3d} {LETTER[l]}{p[0]:16.8E}{p[c]:10.6f}")
                w("")
        w("")
    w("")
    w(' Summary of "ao basis" -> "ao basis" (spherical)')
    w("")
    w(f"  closed shells   = {mol.nelectron // 2:5d}")
    w("  open shells     =     0")
    w("")
    w(f"         Total SCF energy = {mf.e_tot:20.12f}")
    w("")
    w("                       ROHF Final Molecular Orbital Analysis")
    w("                       -------------------------------------")
    w("")
    for k, (e, occ) in enumerate(zip(mf.mo_energy, mf.mo_occ)):
        w(f" Vector {k + 1:4d}  Occ={occ:.6E}  E={e: .6E}".replace("E+", "D+").replace("E-", "D-"))
        w("              MO Center=  0.0D+00,  0.0D+00,  0.0D+00, r^2= 1.0D+00")
        w("")
    w("")
    w("                                 Final MO vectors")
    w("                                 ----------------")
    w("")
    w("")
    w(f" global array: scf_init: MOs[1:{mol.nao},1:{mol.nao}],  handle: -1000 ")
    w("")
    for start in range(0, mol.nao, 6):
        cols = range(start, min(start + 6, mol.nao))
        w("".join(f"{c + 1:12d}" for c in cols) + "  ")
        w("       " + " ".join("-" * 11 for _ in cols))
        for r in range(mol.nao):
            w(f"{r + 1:4d}  " + "".join(f"{coefficients[r, c]:12.5f}" for c in cols))
        w("")
    w(" center of mass")
    w(" --------------")
    with open(os.path.join(out_dir, "h2o_nwchem_ccpvdz.out"), "w") as f:
        f.write("\n".join(lines) + "\n")

    rng = np.random.default_rng(7)
    points = mol.atom_coords()[rng.integers(0, 3, 40)] + rng.normal(scale=0.8, size=(40, 3))
    values = mol.eval_gto("GTOval_sph", points) @ mf.mo_coeff
    with open(os.path.join(out_dir, "h2o_nwchem_ccpvdz.expected.json"), "w") as f:
        json.dump({"points_bohr": points.tolist(), "orbital_values": values.T.tolist()}, f)
        f.write("\n")


if __name__ == "__main__":
    main()
