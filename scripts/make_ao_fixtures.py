#!/usr/bin/env python3
"""Writes tests/fixtures/wavefunctions/NAME.ao.json: single basis functions (atomic orbitals)
and orbitals restricted to a few of them, evaluated by PySCF, for tests/atomic_orbitals.rs.

For each Molden fixture NAME.molden (read back with pyscf.tools.molden.load) it writes
  points      30 points (bohr): 20 near the atoms, 10 in the box padded by 3 bohr
  functions   every basis function by PySCF's label ("O1 3dz^2", "O1 4f-3", "H2 2px"; the atom
              as element + 1-based index), its values at the points, unit-normalised
              (PySCF's value / sqrt(S_ii): PySCF normalises a cartesian shell only as a whole)
  restricted  for a few orbitals (0-based index into the file's orbitals) and sets of labels:
              sum over the set of C_ki * chi_k at the points (PySCF's own coefficients and
              functions, so normalisation cancels)

Run: python scripts/make_ao_fixtures.py   (PySCF 2.x; the output is deterministic)
"""
import json
import os

import numpy as np
from pyscf.tools import molden

DIR = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "tests", "fixtures", "wavefunctions")
SEED = 20250601

# (fixture, [(orbital, [labels])]): water's HOMO is the oxygen lone pair along x (the molecule
# lies in the yz plane); HOMO-1 mixes O 2pz with the hydrogens.
CASES = [
    ("h2o_ccpvtz", [(4, ["O1 2px"]), (4, ["O1 2px", "O1 3px", "O1 3dxz"]),
                    (3, ["O1 2pz", "O1 3dz^2", "O1 4f+0", "H2 1s", "H3 1s"])]),
    ("h2o_cart_631gs", [(4, ["O1 3px", "O1 3dxz"]), (3, ["O1 2pz", "O1 3dzz", "O1 3dxx", "H2 1s"])]),
]


def labels(mol):
    out = []
    for ia, sym, shell, comp in mol.ao_labels(fmt=False):
        out.append(f"{mol.atom_pure_symbol(ia)}{ia + 1} {shell}{comp}")
    return out


def main():
    for name, restricted in CASES:
        mol, _, mo_coeff, _, _, _ = molden.load(os.path.join(DIR, name + ".molden"))
        rng = np.random.default_rng(SEED)
        coords = mol.atom_coords()
        near = coords[rng.integers(0, len(coords), 20)] + rng.normal(scale=0.6, size=(20, 3))
        lo, hi = coords.min(axis=0) - 3.0, coords.max(axis=0) + 3.0
        points = np.vstack([near, rng.uniform(lo, hi, size=(10, 3))])
        ao = mol.eval_gto("GTOval_cart" if mol.cart else "GTOval_sph", points)
        scale = np.sqrt(np.diag(mol.intor("int1e_ovlp")))
        names = labels(mol)
        assert len(set(names)) == len(names)
        out = {
            "source": name + ".molden",
            "points": points.tolist(),
            "functions": {n: (ao[:, k] / scale[k]).tolist() for k, n in enumerate(names)},
            "restricted": [],
        }
        for orbital, chosen in restricted:
            idx = [names.index(c) for c in chosen]
            values = ao[:, idx] @ mo_coeff[idx, orbital]
            out["restricted"].append({"orbital": orbital, "functions": chosen, "values": values.tolist()})
        path = os.path.join(DIR, name + ".ao.json")
        with open(path, "w") as f:
            json.dump(out, f, separators=(",", ":"))
        print(f"{os.path.normpath(path)}: {os.path.getsize(path)} bytes, {len(names)} functions")


if __name__ == "__main__":
    main()
