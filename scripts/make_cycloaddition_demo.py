#!/usr/bin/env python3
"""Generate the bundled diene + SO2 demo (seed 003's picture): assets/cycloaddition/.

    python3 scripts/make_cycloaddition_demo.py [--out-dir assets/cycloaddition]

s-cis 1,3-butadiene and sulfur dioxide placed as in a cheletropic approach, in one
Cartesian frame (Å):

- butadiene in the xy plane, its C2 axis along y: C1/C4 at (±1.45, 0, 0), C2/C3 at
  (±0.67, 1.18, 0) (C=C 1.34 Å, C–C 1.47 Å as the geometry below gives), H on the outside;
- SO2's sulfur above the C1…C4 midpoint at z = 2.8 Å, its O–S–O plane the yz plane, the
  oxygens pointing up and away from the diene (S=O 1.43 Å, O–S–O 119°), so its π* (S p_x)
  points at the termini.

Each molecule is its own RHF/6-31G* calculation in PySCF (symmetry off, so the coordinates
are kept), written with pyscf.tools.molden.from_scf and gzipped reproducibly (orbital signs
fixed: each MO's largest coefficient positive; gzip mtime 0, no name). The viewer shows the
butadiene HOMO (its π orbital, lobes on C1 and C4) and the SO2 LUMO (π*, largest on S), both
translucent, glowing where the two molecules' lobes overlap.
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
from pyscf import gto, lib, scf
from pyscf.tools import molden

HARTREE_EV = 27.211386245988


def butadiene() -> list[tuple[str, tuple[float, float, float]]]:
    """s-cis butadiene in the xy plane, C2 axis along y, termini on the x axis."""
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
    # Hydrogens: H on C2 along the bisector outside; two on C1 at 120°.
    out2 = (c2 - c1) / np.linalg.norm(c2 - c1) + np.array([1.0, 0.0])
    out2 /= np.linalg.norm(out2)
    h2 = c2 + ch * out2
    b = (c1 - c2) / np.linalg.norm(c1 - c2)
    rot = lambda v, a: np.array([v[0] * np.cos(a) - v[1] * np.sin(a), v[0] * np.sin(a) + v[1] * np.cos(a)])
    h1a = c1 + ch * rot(b, np.deg2rad(60.0))
    h1b = c1 + ch * rot(b, np.deg2rad(-60.0))
    for h in (h2, h1a, h1b):
        atoms.append(("H", h))
        atoms.append(("H", h * [-1, 1]))
    return [(s, (float(p[0]), float(p[1]), 0.0)) for s, p in atoms]


def so2(height: float = 2.8) -> list[tuple[str, tuple[float, float, float]]]:
    """SO2 with S at (0, 0, height), O–S–O in the yz plane, the oxygens pointing up."""
    so, half = 1.43, np.deg2rad(119.0 / 2)
    dy, dz = so * np.sin(half), so * np.cos(half)
    return [("S", (0.0, 0.0, height)), ("O", (0.0, dy, height + dz)), ("O", (0.0, -dy, height + dz))]


def scf_of(atoms) -> tuple[gto.Mole, scf.hf.RHF]:
    mol = gto.M(atom=atoms, unit="Angstrom", basis="6-31g*", symmetry=False, verbose=0)
    mf = scf.RHF(mol)
    mf.conv_tol = 1e-10
    mf.kernel()
    if not mf.converged:
        raise RuntimeError("SCF did not converge")
    # Reproducible signs: each orbital's largest coefficient positive.
    c = np.array(mf.mo_coeff)
    rows = np.argmax(np.abs(c), axis=0)
    mf.mo_coeff = c * np.sign(c[rows, np.arange(c.shape[1])])
    return mol, mf


def write_molden_gz(mol, mf, path: Path) -> int:
    with tempfile.TemporaryDirectory() as tmp:
        raw = Path(tmp) / "out.molden"
        molden.from_scf(mf, str(raw))
        text = raw.read_bytes()
    buf = io.BytesIO()
    with gzip.GzipFile(filename="", mode="wb", fileobj=buf, mtime=0, compresslevel=9) as gz:
        gz.write(text)
    path.write_bytes(buf.getvalue())
    return len(buf.getvalue())


def p_weight(mol, coeff, element: str, axis: str) -> float:
    """Share of |c|² on the p functions along `axis` of `element`."""
    labels = mol.ao_labels(fmt=False)
    w = coeff**2
    on = sum(w[i] for i, (_, sym, shell, kind) in enumerate(labels) if sym == element and kind == axis and "p" in shell)
    return float(on / w.sum())


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out-dir", default="assets/cycloaddition", type=Path)
    args = ap.parse_args()
    # One thread: the same sums in the same order, so the same digits in the files every run.
    lib.num_threads(1)
    args.out_dir.mkdir(parents=True, exist_ok=True)
    t0 = time.time()
    lines = []
    # Butadiene's HOMO is its π (C p_z); SO2's LUMO its π* (S p_x, across the O–S–O plane),
    # whose lobes point at the diene's termini.
    cases = (("butadiene", butadiene(), "homo", "C", "z"), ("so2", so2(), "lumo", "S", "x"))
    for name, atoms, which, element, axis in cases:
        mol, mf = scf_of(atoms)
        occ = np.asarray(mf.mo_occ)
        homo = int(np.nonzero(occ > 0)[0].max())
        idx = homo if which == "homo" else homo + 1
        energy = float(mf.mo_energy[idx])
        size = write_molden_gz(mol, mf, args.out_dir / f"{name}.molden.gz")
        share = p_weight(mol, np.asarray(mf.mo_coeff)[:, idx], element, axis)
        line = (
            f"{name}: RHF/6-31G* E = {mf.e_tot:.6f} Eh; {which.upper()} = MO {idx + 1} "
            f"(Molden's numbering), {energy:.5f} Eh = {energy * HARTREE_EV:.3f} eV; "
            f"{share:.0%} of |c|² on {element} p_{axis}; {size} bytes"
        )
        print(line)
        lines.append(line)
        for sym, xyz in atoms:
            print(f"    {sym} {xyz[0]:9.4f} {xyz[1]:9.4f} {xyz[2]:9.4f} Å")
    readme = args.out_dir / "README.md"
    readme.write_text(
        "# Diene + SO₂: the bundled translucent demo\n\n"
        "s-cis 1,3-butadiene and SO₂ placed as in a cheletropic approach (SO₂'s sulfur 2.8 Å above\n"
        "the middle of the diene's termini), one frame for both. Each molecule: RHF/6-31G* in PySCF,\n"
        "written as Molden. The viewer shows butadiene's HOMO and SO₂'s LUMO translucent\n"
        "(`cargo run --release -- --demo cycloaddition`).\n\n"
        "Regenerate: `python3 scripts/make_cycloaddition_demo.py`\n\n"
        + "".join(f"- {l}\n" for l in lines)
    )
    print(f"done in {time.time() - t0:.1f} s")
    return 0


if __name__ == "__main__":
    sys.exit(main())
