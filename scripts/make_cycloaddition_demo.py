#!/usr/bin/env python3
"""Generate the bundled diene + SO2 demo (Koide and Miyata's picture): assets/cycloaddition/.

    python3 scripts/make_cycloaddition_demo.py [--out-dir assets/cycloaddition]

s-cis 1,3-butadiene and sulfur dioxide placed as in a cheletropic approach, both in one
Cartesian frame, so the two files line up when opened together. Coordinates (Å; bohr =
Å / 0.52917721092):

    butadiene (planar s-cis, the xy plane, C2 axis along y, termini C1/C4 on the x axis)
      C1   1.4843   0.0000   0.0000
      C2   0.7350   1.1109   0.0000
      C3  -0.7350   1.1109   0.0000
      C4  -1.4843   0.0000   0.0000
      H2   1.2444   2.0689   0.0000      (on C2)
      H3  -1.2444   2.0689   0.0000      (on C3)
      H1o  2.5667   0.0757   0.0000      (on C1, outer)
      H4o -2.5667   0.0757   0.0000      (on C4, outer)
      H1i  1.0087  -0.9752   0.0000      (on C1, inner)
      H4i -1.0087  -0.9752   0.0000      (on C4, inner)
    SO2 (O-S-O in the yz plane, S nearest the diene, the oxygens pointing up and away)
      S    0.0000   0.0000   2.8000
      O    0.0000   1.2321   3.5258
      O    0.0000  -1.2321   3.5258

Butadiene: C=C 1.34 Å, C-C 1.47 Å, C-H 1.085 Å, C=C-C 124°, H-C-H and H-C=C 120° at the
termini, H-C2 on the bisector (118°). SO2: S=O 1.43 Å, O-S-O 119°. The sulfur sits 2.80 Å
above the midpoint of C1...C4 (the origin), 3.17 Å from C1 and from C4. The O-S-O plane
contains the diene's C2 axis and is perpendicular to the diene's plane, so the yz plane is a
mirror plane of the pair: butadiene's HOMO (π, C p_z, opposite signs on C1 and C4) and SO2's
LUMO (π*, S p_x, perpendicular to the O-S-O plane) are both odd under it, and their lobes
at the termini and on S meet.

Each molecule is its own RHF/6-31G* calculation in PySCF (spherical d, symmetry off, so the
coordinates above are kept), written with pyscf.tools.molden.from_scf (every MO) and gzipped.
The output is reproducible: one thread; each MO's sign fixed (its largest coefficient
positive); MO coefficients rounded to 8 decimals (orthonormality kept to ~1e-8, files about
2.5x smaller); gzip level 9 with no name and mtime 0 in the header. It also writes
README.md beside the files (also printed here) and reads both files back with
pyscf.tools.molden.load to check them.
"""

from __future__ import annotations

import argparse
import gzip
import io
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
import pyscf
from pyscf import gto, lib, scf
from pyscf.tools import molden

HARTREE_EV = 27.211386245988
BOHR = lib.param.BOHR  # Å per bohr
BASIS = "6-31g*"
DECIMALS = 8  # MO coefficients written to this many decimals
S_HEIGHT = 2.8  # Å, sulfur above the C1...C4 midpoint

BUTADIENE_LABELS = ["C1", "C2", "C3", "C4", "H2", "H3", "H1o", "H4o", "H1i", "H4i"]
SO2_LABELS = ["S", "O", "O"]

Atoms = list[tuple[str, tuple[float, float, float]]]


def butadiene() -> Atoms:
    """s-cis butadiene in the xy plane, C2 axis along y, termini C1 (+x) and C4 (-x) on the x axis."""
    cc_double, cc_single, ch = 1.34, 1.47, 1.085
    # C2/C3 at (±x2, y2); C1/C4 at (±x1, 0); the C1=C2 bond 1.34 Å, C2–C3 1.47 Å.
    x2 = cc_single / 2
    angle = np.deg2rad(124.0)  # C1=C2–C3
    # Direction C2→C1 makes 124° with C2→C3 (−x): rotate −x by −124° about z (towards −y).
    d = np.array([np.cos(np.pi - angle), -np.sin(np.pi - angle)])
    c2 = np.array([x2, 0.0])
    c1 = c2 + cc_double * d
    shift = -c1[1]  # put the termini on y = 0
    c1[1] += shift
    c2[1] += shift
    atoms = [("C", c1), ("C", c2), ("C", c2 * [-1, 1]), ("C", c1 * [-1, 1])]

    def rot(v, a):
        return np.array([v[0] * np.cos(a) - v[1] * np.sin(a), v[0] * np.sin(a) + v[1] * np.cos(a)])

    # Hydrogens: H on C2 along the outer bisector; two on C1 at 120° to C1=C2.
    out2 = (c2 - c1) / np.linalg.norm(c2 - c1) + np.array([1.0, 0.0])
    out2 /= np.linalg.norm(out2)
    h2 = c2 + ch * out2
    b = (c1 - c2) / np.linalg.norm(c1 - c2)
    h1a = c1 + ch * rot(b, np.deg2rad(60.0))
    h1b = c1 + ch * rot(b, np.deg2rad(-60.0))
    for h in (h2, h1a, h1b):
        atoms.append(("H", h))
        atoms.append(("H", h * [-1, 1]))
    return [(s, (float(p[0]), float(p[1]), 0.0)) for s, p in atoms]


def so2(height: float = S_HEIGHT) -> Atoms:
    """SO2 with S at (0, 0, height), O–S–O in the yz plane, the oxygens pointing up (+z)."""
    so, half = 1.43, np.deg2rad(119.0 / 2)
    dy, dz = so * np.sin(half), so * np.cos(half)
    return [("S", (0.0, 0.0, height)), ("O", (0.0, dy, height + dz)), ("O", (0.0, -dy, height + dz))]


def check_geometry(diene: Atoms, so2_atoms: Atoms) -> None:
    """The bond lengths and angles the docstring promises."""
    p = {lab: np.array(xyz) for lab, (_, xyz) in zip(BUTADIENE_LABELS, diene)}

    def dist(a, b):
        return float(np.linalg.norm(a - b))

    def ang(a, b, c):
        u, v = a - b, c - b
        return float(np.degrees(np.arccos(u @ v / np.linalg.norm(u) / np.linalg.norm(v))))

    assert abs(dist(p["C1"], p["C2"]) - 1.34) < 1e-9 and abs(dist(p["C2"], p["C3"]) - 1.47) < 1e-9
    assert abs(ang(p["C1"], p["C2"], p["C3"]) - 124.0) < 1e-9
    for h, c in (("H2", "C2"), ("H1o", "C1"), ("H1i", "C1")):
        assert abs(dist(p[h], p[c]) - 1.085) < 1e-9
    s, o1, o2 = (np.array(xyz) for _, xyz in so2_atoms)
    assert abs(dist(s, o1) - 1.43) < 1e-9 and abs(ang(o1, s, o2) - 119.0) < 1e-9
    mid = (p["C1"] + p["C4"]) / 2
    assert np.allclose(s[:2], mid[:2]) and min(o1[2], o2[2]) > s[2] > 0


def scf_of(atoms: Atoms) -> tuple[gto.Mole, scf.hf.RHF]:
    mol = gto.M(atom=atoms, unit="Angstrom", basis=BASIS, cart=False, symmetry=False, verbose=0)
    mf = scf.RHF(mol)
    mf.conv_tol = 1e-10
    mf.kernel()
    if not mf.converged:
        raise RuntimeError(f"SCF did not converge for {mol.atom}")
    # Reproducible signs: each orbital's largest coefficient positive; then round.
    c = np.array(mf.mo_coeff)
    rows = np.argmax(np.abs(c), axis=0)
    c = c * np.sign(c[rows, np.arange(c.shape[1])])
    mf.mo_coeff = np.round(c, DECIMALS) + 0.0  # + 0.0: no "-0" in the file
    return mol, mf


def write_molden_gz(mf, path: Path) -> tuple[int, int]:
    """Molden text of `mf` gzipped to `path`; returns (bytes on disk, bytes uncompressed)."""
    with tempfile.TemporaryDirectory() as tmp:
        raw = Path(tmp) / "out.molden"
        molden.from_scf(mf, str(raw))
        text = raw.read_bytes()
    buf = io.BytesIO()
    with gzip.GzipFile(filename="", mode="wb", fileobj=buf, mtime=0, compresslevel=9) as gz:
        gz.write(text)
    path.write_bytes(buf.getvalue())
    return len(buf.getvalue()), len(text)


def weight(mol, coeff, atom: int | None = None, l: str | None = None, axis: str | None = None) -> float:
    """Share of |c|² on the AOs matching atom index, shell letter (s/p/d) and axis."""
    w = np.asarray(coeff) ** 2
    on = 0.0
    for i, (ia, _, shell, kind) in enumerate(mol.ao_labels(fmt=False)):
        if (atom is None or ia == atom) and (l is None or l in shell) and (axis is None or kind == axis):
            on += w[i]
    return float(on / w.sum())


def top_aos(mol, coeff, n: int = 4) -> str:
    labels = mol.ao_labels()
    order = np.argsort(-np.abs(coeff), kind="stable")[:n]
    return ", ".join(f"{labels[i].strip()} {coeff[i]:+.3f}" for i in order)


def pz_on(mol, coeff, atom: int) -> float:
    """Sum of the atom's p_z coefficients (the sign of its π lobe on +z)."""
    return float(sum(coeff[i] for i, (ia, _, sh, k) in enumerate(mol.ao_labels(fmt=False)) if ia == atom and "p" in sh and k == "z"))


def read_back(path: Path, mol: gto.Mole, mf) -> str:
    """Load the gzipped file with pyscf.tools.molden.load and compare with what was written."""
    with tempfile.TemporaryDirectory() as tmp:
        raw = Path(tmp) / "in.molden"
        raw.write_bytes(gzip.decompress(path.read_bytes()))
        mol2, ene, coeff, occ, _, _ = molden.load(str(raw))
    assert mol2.natm == mol.natm and [mol2.atom_pure_symbol(i) for i in range(mol2.natm)] == [
        mol.atom_pure_symbol(i) for i in range(mol.natm)
    ]
    dx = float(np.abs(mol2.atom_coords() - mol.atom_coords()).max())
    de = float(np.abs(np.asarray(ene) - mf.mo_energy).max())
    dc = float(np.abs(np.asarray(coeff) - mf.mo_coeff).max())
    assert mol2.nao_nr() == mol.nao_nr() and np.asarray(coeff).shape == mf.mo_coeff.shape
    assert dx < 1e-10 and de < 1e-8 and dc < 1e-10 and np.allclose(occ, mf.mo_occ)
    s = mol2.intor("int1e_ovlp")
    ortho = float(np.abs(coeff.T @ s @ coeff - np.eye(coeff.shape[1])).max())
    return (
        f"read back with molden.load: {mol2.natm} atoms, {mol2.nao_nr()} AOs, {coeff.shape[1]} MOs, "
        f"{int(round(np.sum(occ)))} electrons; max |Δ| coords {dx:.0e} bohr, energies {de:.0e} Eh, "
        f"coefficients {dc:.0e}; |CᵀSC − 1| ≤ {ortho:.0e}"
    )


def coord_table(atoms: Atoms, labels: list[str]) -> list[str]:
    rows = ["| atom | x (Å) | y (Å) | z (Å) | x (bohr) | y (bohr) | z (bohr) |", "|---|---:|---:|---:|---:|---:|---:|"]
    for lab, (_, xyz) in zip(labels, atoms):
        a = " | ".join(f"{v:.4f}" for v in xyz)
        b = " | ".join(f"{v / BOHR:.4f}" for v in xyz)
        rows.append(f"| {lab} | {a} | {b} |")
    return rows


def main(argv: list[str] | None = None) -> int:
    repo = Path(__file__).resolve().parent.parent
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out-dir", default=repo / "assets" / "cycloaddition", type=Path)
    args = ap.parse_args(argv)
    # One thread: the same sums in the same order, so the same digits in the files every run.
    lib.num_threads(1)
    args.out_dir.mkdir(parents=True, exist_ok=True)
    t0 = time.perf_counter()

    diene, sulfur = butadiene(), so2()
    check_geometry(diene, sulfur)
    facts, results = [], {}
    # Butadiene's HOMO is its π (C p_z); SO2's LUMO its π* (S p_x, across the O–S–O plane).
    for name, atoms, which in (("butadiene", diene, "homo"), ("so2", sulfur, "lumo")):
        t1 = time.perf_counter()
        mol, mf = scf_of(atoms)
        homo = int(np.nonzero(np.asarray(mf.mo_occ) > 0)[0].max())
        idx = homo if which == "homo" else homo + 1
        path = args.out_dir / f"{name}.molden.gz"
        size, raw = write_molden_gz(mf, path)
        check = read_back(path, mol, mf)
        results[name] = (mol, mf, idx, size, raw)
        e = float(mf.mo_energy[idx])
        print(
            f"{name}: RHF/{BASIS.upper()} converged ({getattr(mf, 'cycles', '?')} cycles) E = {mf.e_tot:.8f} Eh, "
            f"{mol.nao_nr()} AOs; {which.upper()} = MO {idx + 1} (1-based, as Molden counts; 0-based {idx}), "
            f"e = {e:.6f} Eh = {e * HARTREE_EV:.3f} eV; {path} {size} bytes ({raw} uncompressed); "
            f"{time.perf_counter() - t1:.1f} s"
        )
        print(f"    {check}")

    # The orbitals' character.
    mol_b, mf_b, homo_b, size_b, _ = results["butadiene"]
    c_b = mf_b.mo_coeff[:, homo_b]
    pz_c = weight(mol_b, c_b, l="p", axis="z")
    lobes = [pz_on(mol_b, c_b, a) for a in range(4)]
    assert pz_c > 0.95, "butadiene's HOMO is not a π orbital"
    assert all("C" in lab and "pz" in lab for lab in np.asarray(mol_b.ao_labels())[np.argsort(-np.abs(c_b))[:4]])
    assert lobes[0] * lobes[3] < 0 and abs(lobes[0]) > abs(lobes[1]), "HOMO is not ψ2 (C1/C4 large, opposite)"
    facts.append(
        f"Butadiene HOMO (MO {homo_b + 1}) is π: {pz_c:.1%} of |c|² on C p_z; largest AOs {top_aos(mol_b, c_b)}; "
        f"summed p_z coefficients C1..C4 {', '.join(f'{v:+.3f}' for v in lobes)} "
        f"(ψ2: C1 and C4 largest and of opposite sign, odd under the yz mirror)."
    )
    mol_s, mf_s, lumo_s, size_s, _ = results["so2"]
    c_s = mf_s.mo_coeff[:, lumo_s]
    on_atom = [weight(mol_s, c_s, atom=a) for a in range(3)]
    s_px, px_all = weight(mol_s, c_s, atom=0, l="p", axis="x"), weight(mol_s, c_s, l="p", axis="x")
    assert int(np.argmax(on_atom)) == 0, "SO2's LUMO is not largest on S"
    assert "S" in mol_s.ao_labels()[int(np.argmax(np.abs(c_s)))] and px_all > 0.8, "SO2's LUMO is not π* (p_x)"
    facts.append(
        f"SO2 LUMO (MO {lumo_s + 1}) is π*: |c|² on S {on_atom[0]:.1%}, O {on_atom[1]:.1%} + {on_atom[2]:.1%}; "
        f"S p_x {s_px:.1%}, all p_x {px_all:.1%} (perpendicular to the O–S–O plane, odd under the yz mirror); "
        f"largest AOs {top_aos(mol_s, c_s)}."
    )
    c1, c4, s_at = np.array(diene[0][1]), np.array(diene[3][1]), np.array(sulfur[0][1])
    ovlp = gto.intor_cross("int1e_ovlp", mol_b, mol_s)
    s_fmo = float(c_b @ ovlp @ c_s)
    facts.append(
        f"Approach: S {s_at[2]:.2f} Å above the C1…C4 midpoint and the diene plane (z = 0); S–C1 = S–C4 = "
        f"{np.linalg.norm(s_at - c1):.3f} Å; C1…C4 {np.linalg.norm(c1 - c4):.3f} Å. Both orbitals are odd under "
        f"the yz mirror, so they may overlap: <HOMO(diene)|LUMO(SO2)> = {s_fmo:+.4f}."
    )
    for f in facts:
        print(f)

    e_h, e_l = float(mf_b.mo_energy[homo_b]), float(mf_s.mo_energy[lumo_s])
    readme = "\n".join(
        [
            "# Diene + SO₂: the bundled translucent demo",
            "",
            "s-cis 1,3-butadiene and SO₂ placed as in a cheletropic approach, one Cartesian frame for",
            "both, so the two files line up when opened together. The viewer shows butadiene's HOMO and",
            "SO₂'s LUMO translucent (`cargo run --release -- --demo cycloaddition`).",
            "",
            f"- `butadiene.molden.gz` ({size_b} bytes): butadiene, every MO, gzipped Molden.",
            f"- `so2.molden.gz` ({size_s} bytes): SO₂, every MO, gzipped Molden.",
            "",
            f"Each molecule is its own RHF/6-31G* calculation (PySCF {pyscf.__version__}, spherical d, symmetry",
            "off), written by `pyscf.tools.molden.from_scf`; each MO's largest coefficient is positive and",
            f"the coefficients are rounded to {DECIMALS} decimals. Regenerate (deterministic, a few seconds):",
            "",
            "    python3 scripts/make_cycloaddition_demo.py [--out-dir assets/cycloaddition]",
            "",
            "MO numbers are 1-based, as Molden counts them:",
            "",
            f"- butadiene: E = {mf_b.e_tot:.6f} Eh; HOMO = MO {homo_b + 1}, {e_h:.5f} Eh = {e_h * HARTREE_EV:.3f} eV "
            f"(π, ψ2: C p_z, largest and of opposite sign on C1 and C4)",
            f"- SO₂: E = {mf_s.e_tot:.6f} Eh; LUMO = MO {lumo_s + 1}, {e_l:.5f} Eh = {e_l * HARTREE_EV:.3f} eV "
            f"(π*: {on_atom[0]:.0%} of |c|² on S, S p_x)",
            "",
            "Geometry: butadiene planar in the xy plane, its C2 axis along y, C=C 1.34 Å, C–C 1.47 Å,",
            "C–H 1.085 Å, C=C–C 124°; SO₂ with S=O 1.43 Å, O–S–O 119°, its O–S–O plane the yz plane,",
            f"S {S_HEIGHT:.2f} Å above the midpoint of C1…C4 ({np.linalg.norm(s_at - c1):.2f} Å from each), the oxygens",
            f"pointing away from the diene. Overlap <HOMO(diene)|LUMO(SO₂)> = {s_fmo:+.4f} (both odd under the yz mirror).",
            "",
            *coord_table(diene, BUTADIENE_LABELS),
            *coord_table(sulfur, SO2_LABELS)[2:],
            "",
        ]
    )
    (args.out_dir / "README.md").write_text(readme)
    print()
    print(readme)
    print(f"done in {time.perf_counter() - t0:.1f} s")
    return 0


if __name__ == "__main__":
    sys.exit(main())
