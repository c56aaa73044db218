#!/usr/bin/env python3
"""Generate orbcloud's bundled demo volume, assets/demo.cube.gz.

    python3 scripts/make_assets.py [--out assets/demo.cube.gz]

Formaldehyde (H2CO), B3LYP/6-31G* in PySCF, symmetry off so the input
coordinates are kept: C at the origin, C=O along +x, the molecule in the xy
plane (the viewer's default camera looks along -z, so it sees the molecule face on). The HOMO (MO 8, the in-plane oxygen lone pair, 2b2 in the usual
yz-plane labelling: an O 2p_x lobe pair of opposite sign mixed with the
antisymmetric combination of the C-H bonds) is written with
pyscf.tools.cubegen.orbital on a 48x48x48 grid with a 3.5 bohr margin and
gzipped at level 9.

The output is reproducible: the orbital's sign is fixed (its largest AO
coefficient is made positive), the cube's time-stamp line is replaced by a
fixed description and the gzip header carries no name or time.

The functions here (`run_scf`, `write_orbital_cube`) also serve other
scripts, e.g. scripts/make_bench_cube.py.
"""

from __future__ import annotations

import argparse
import gzip
import os
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
import pyscf
from pyscf import dft, gto, scf
from pyscf.tools import cubegen

HARTREE_EV = 27.211386245988

# Formaldehyde, experimental-like geometry (Å): r(CO) 1.205, r(CH) 1.111,
# angle HCH 116.1 degrees. C at the origin, O on +x, H atoms in the xy plane.
_HCH = np.deg2rad(116.1)
_RCH = 1.111
FORMALDEHYDE = [
    ("C", (0.0, 0.0, 0.0)),
    ("O", (1.205, 0.0, 0.0)),
    ("H", (-_RCH * np.cos(_HCH / 2), _RCH * np.sin(_HCH / 2), 0.0)),
    ("H", (-_RCH * np.cos(_HCH / 2), -_RCH * np.sin(_HCH / 2), 0.0)),
]

DEMO_GRID = 48
DEMO_MARGIN = 3.5  # bohr
DEMO_METHOD = "b3lyp"
DEMO_BASIS = "6-31g*"


def build_mol(atoms, basis: str = DEMO_BASIS, charge: int = 0, spin: int = 0) -> gto.Mole:
    mol = gto.Mole()
    mol.atom = [(sym, tuple(float(c) for c in xyz)) for sym, xyz in atoms]
    mol.unit = "Angstrom"
    mol.basis = basis
    mol.charge = charge
    mol.spin = spin
    mol.symmetry = False
    mol.verbose = 0
    mol.build()
    return mol


def run_scf(mol: gto.Mole, method: str = DEMO_METHOD):
    """Closed-shell SCF: method "hf" for RHF, otherwise an RKS functional name."""
    if method.lower() in ("hf", "rhf"):
        mf = scf.RHF(mol)
    else:
        mf = dft.RKS(mol)
        mf.xc = method
    mf.conv_tol = 1e-10
    mf.kernel()
    if not mf.converged:
        raise RuntimeError(f"SCF did not converge for {mol.atom}")
    return mf


def orbital_index(mf, which: str | int) -> int:
    """0-based MO index from "homo", "lumo", "homo-1", "lumo+2" or an integer."""
    if isinstance(which, int):
        return which
    occ = np.asarray(mf.mo_occ)
    homo = int(np.nonzero(occ > 0)[0].max())
    w = which.lower().replace(" ", "")
    for base, idx in (("homo", homo), ("lumo", homo + 1)):
        if w.startswith(base):
            rest = w[len(base):]
            return idx + (int(rest) if rest else 0)
    return int(w)


def fixed_sign(coeff: np.ndarray) -> np.ndarray:
    """The orbital with its largest-magnitude coefficient made positive."""
    k = int(np.argmax(np.abs(coeff)))
    return coeff if coeff[k] >= 0 else -coeff


def write_orbital_cube(
    mol: gto.Mole,
    mf,
    path: str | os.PathLike,
    which: str | int = "homo",
    n: int | tuple[int, int, int] = DEMO_GRID,
    margin: float = DEMO_MARGIN,
    title: str | None = None,
    gzip_level: int | None = None,
) -> dict:
    """Write one MO of `mf` as a Gaussian cube file (gzipped if gzip_level is set).

    `n` is the number of points per axis (an int for a cubic grid).
    Returns a description: index, label, energy (Hartree), dims, spacing, bytes.
    """
    nx, ny, nz = (n, n, n) if isinstance(n, int) else tuple(n)
    idx = orbital_index(mf, which)
    coeff = fixed_sign(np.asarray(mf.mo_coeff)[:, idx])
    energy = float(mf.mo_energy[idx])
    label = which if isinstance(which, str) else f"MO {idx + 1}"

    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    with tempfile.TemporaryDirectory() as tmp:
        raw = Path(tmp) / "orbital.cube"
        cubegen.orbital(mol, str(raw), coeff, nx=nx, ny=ny, nz=nz, margin=margin)
        lines = raw.read_text().splitlines(keepends=True)

    # Line 2 of cubegen's output carries a time stamp; replace it with a fixed description.
    xc = getattr(mf, "xc", "HF")
    lines[0] = f"{title or 'Orbital value in real space (1/Bohr^3)'}\n"
    lines[1] = (
        f"MO {idx + 1} ({label}) E={energy:.6f} Eh  {str(xc).upper()}/{mol.basis}  "
        f"PySCF {pyscf.__version__}\n"
    )
    text = "".join(lines).encode("ascii")

    if gzip_level is not None:
        with open(path, "wb") as fh:
            with gzip.GzipFile(filename="", mode="wb", fileobj=fh, compresslevel=gzip_level, mtime=0) as gz:
                gz.write(text)
    else:
        path.write_bytes(text)

    cube = cubegen.Cube(mol, nx, ny, nz, margin=margin)
    spacing = np.diag(np.asarray(cube.box)) / (np.array([nx, ny, nz]) - 1)
    return {
        "index": idx,
        "label": label,
        "energy": energy,
        "dims": (nx, ny, nz),
        "spacing": tuple(float(s) for s in spacing),
        "origin": tuple(float(o) for o in cube.boxorig),
        "bytes": path.stat().st_size,
        "raw_bytes": len(text),
        "nao": mol.nao_nr(),
    }


def describe(info: dict, path) -> str:
    nx, ny, nz = info["dims"]
    sx, sy, sz = info["spacing"]
    return (
        f"{path}: MO {info['index'] + 1} ({info['label']}, 0-based {info['index']}), "
        f"E = {info['energy']:.6f} Eh = {info['energy'] * HARTREE_EV:.3f} eV; "
        f"grid {nx}x{ny}x{nz}, spacing {sx:.4f} {sy:.4f} {sz:.4f} bohr; "
        f"{info['nao']} AOs; {info['bytes']} bytes on disk ({info['raw_bytes']} uncompressed)"
    )


def main(argv: list[str] | None = None) -> int:
    repo = Path(__file__).resolve().parent.parent
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--out", default=str(repo / "assets" / "demo.cube.gz"))
    ap.add_argument("--size", type=int, default=DEMO_GRID, help="points per axis (default 48)")
    ap.add_argument("--orbital", default="homo", help="homo, lumo, homo-1, ... or a 0-based index")
    args = ap.parse_args(argv)

    t0 = time.perf_counter()
    mol = build_mol(FORMALDEHYDE)
    mf = run_scf(mol)
    occ = np.asarray(mf.mo_occ)
    homo = int(np.nonzero(occ > 0)[0].max())
    print(f"H2CO {DEMO_METHOD.upper()}/{DEMO_BASIS}: E = {mf.e_tot:.8f} Eh, {mol.nao_nr()} AOs, HOMO = MO {homo + 1}")
    for i in range(max(0, homo - 2), min(len(occ), homo + 3)):
        tag = "HOMO" if i == homo else ("LUMO" if i == homo + 1 else "")
        print(f"  MO {i + 1:3d}  occ {occ[i]:.1f}  e = {mf.mo_energy[i]: .6f} Eh {tag}")

    out = Path(args.out)
    info = write_orbital_cube(mol, mf, out, which=args.orbital, n=args.size,
                              margin=DEMO_MARGIN, gzip_level=9 if out.suffix == ".gz" else None)
    print(describe(info, out))
    print(f"orbital energy = {info['energy']:.6f} Eh, grid dims = {'x'.join(map(str, info['dims']))}")
    print(f"done in {time.perf_counter() - t0:.1f} s")
    return 0


if __name__ == "__main__":
    sys.exit(main())
