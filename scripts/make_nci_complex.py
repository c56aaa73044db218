"""A 52-atom van der Waals complex for the NCI and GPU benchmarks, made with PySCF: two all-trans
octanes side by side, their carbon planes 4.0 Å apart (as in the crystal) (the parallel alkane dimer, held by
dispersion between facing C–H bonds), HF/6-31G* (296 basis functions), written as

  target/bench/octane_dimer_631gs.molden   PySCF's Molden writer

Not a test fixture (2.6 MB): `scripts/bench_gpu.sh` and `orbcloud bench nci` read it. Run from
the repository root:
    python3 scripts/make_nci_complex.py        (pyscf, numpy; see requirements.txt)
"""

import os
import sys

import numpy as np
from pyscf import gto, scf
from pyscf.tools import molden

OUT = os.path.join("target", "bench", "octane_dimer_631gs.molden")
CC, CH = 1.53, 1.09  # Å
HALF_CCC = np.radians(112.0) / 2
HALF_HCH = np.radians(109.5) / 2
SEPARATION = 4.0  # Å between the two chains' carbon planes


def octane(y: float) -> list[tuple[str, np.ndarray]]:
    """An all-trans octane in the plane y = const, its chain along x, zigzag in z."""
    n = 8
    step, rise = CC * np.sin(HALF_CCC), CC * np.cos(HALF_CCC)
    # One carbon beyond each end stands for the terminal H in the chain's plane.
    carbons = [np.array([i * step, (i % 2) * rise, 0.0]) for i in range(-1, n + 1)]
    atoms = [("C", c) for c in carbons[1:-1]]
    out_of_plane = np.array([0.0, 0.0, 1.0])
    for i in range(1, n + 1):
        c, before, after = carbons[i], carbons[i - 1], carbons[i + 1]
        u = (before - c) / np.linalg.norm(before - c) + (after - c) / np.linalg.norm(after - c)
        away = -u / np.linalg.norm(u)
        for sign in (1, -1):
            d = away * np.cos(HALF_HCH) + sign * out_of_plane * np.sin(HALF_HCH)
            atoms.append(("H", c + CH * d))
        for end in (before, after) if i in (1, n) else ():
            if (i == 1 and end is before) or (i == n and end is after):
                atoms.append(("H", c + CH * (end - c) / np.linalg.norm(end - c)))
    # The chain's plane is xy here (zigzag in y); turn it so the zigzag lies in z and the
    # hydrogens point along ±y, then place the plane at y.
    turned = [(e, np.array([p[0], p[2], p[1]]) + np.array([0.0, y, 0.0])) for e, p in atoms]
    return turned


def main() -> None:
    atoms = octane(0.0) + octane(SEPARATION)
    assert len(atoms) == 52, len(atoms)
    mol = gto.M(atom=[(e, tuple(p)) for e, p in atoms], basis="6-31g*", unit="Angstrom", verbose=0)
    d = np.linalg.norm(mol.atom_coords()[:, None] - mol.atom_coords()[None], axis=-1)
    closest = d[np.triu_indices(len(atoms), 1)].min() * 0.529177
    assert closest > 0.9, f"atoms {closest:.2f} Å apart"
    mf = scf.RHF(mol).density_fit()
    mf.conv_tol = 1e-7
    mf.run()
    if not mf.converged:
        sys.exit("the SCF did not converge")
    os.makedirs(os.path.dirname(OUT), exist_ok=True)
    molden.from_scf(mf, OUT)
    print(OUT, mol.natm, "atoms", mol.nao, "basis functions", mf.e_tot)


if __name__ == "__main__":
    main()
