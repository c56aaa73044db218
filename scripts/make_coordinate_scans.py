#!/usr/bin/env python3
"""Write the scan fixtures of other coordinates than a dihedral, tests/fixtures/scans/:

    OMP_NUM_THREADS=1 python3 scripts/make_coordinate_scans.py [--out tests/fixtures/scans]

(PySCF and numpy; a few seconds.)

water_bend/    H-O-H from 80 to 160 degrees every 10 (9 frames), O-H 0.96 A, RHF/6-31G. Each
               geometry in the standard orientation of a symmetric bend: O at the origin, the
               bisector along +y, the molecule in the xy plane, so both hydrogens move from frame
               to frame (a reader must not assume one side stays put).
water_stretch/ the second O-H from 0.80 to 1.60 A every 0.2 (5 frames) at 104.5 degrees, the
               first O-H 0.96 A fixed in place, RHF/STO-3G.
water_path/    four frames in which the angle and the second O-H change together (95 -> 125
               degrees, 0.90 -> 1.20 A), RHF/STO-3G, with a manifest `water_path.scan.toml` of
               coordinate = "path" and align = false.
water_turned/  the same four frames, each after the first turned and moved rigidly (as a program
               that writes every geometry in its own standard orientation would), with a
               manifest of coordinate = "path" and align = true.

Every frame: symmetry off, cartesian=False, conv_tol 1e-10, the default initial guess, one
thread; Molden files from pyscf.tools.molden (all orbitals), gzip level 9 with mtime 0.
Atom order O, H1, H2: the bend is angle 2-1-3, the stretch distance 1-3 (1-based).
"""

from __future__ import annotations

import argparse
import gzip
import io
import math
from pathlib import Path

import numpy as np
from pyscf import gto, lib, scf
from pyscf.tools import molden


def water(angle_deg: float, oh1: float, oh2: float) -> list[tuple[str, tuple[float, float, float]]]:
    """Water with its bisector along +y: H1 at +angle/2 from +y, H2 at -angle/2."""
    half = math.radians(angle_deg) / 2
    return [
        ("O", (0.0, 0.0, 0.0)),
        ("H", (oh1 * math.sin(half), oh1 * math.cos(half), 0.0)),
        ("H", (-oh2 * math.sin(half), oh2 * math.cos(half), 0.0)),
    ]


def stretched(oh2: float) -> list[tuple[str, tuple[float, float, float]]]:
    """Water at 104.5 degrees, H1 fixed at 0.96 A, H2 at `oh2` A along its own direction."""
    return water(104.5, 0.96, oh2)


def write_molden(path: Path, atoms, basis: str) -> float:
    mol = gto.M(atom=atoms, basis=basis, unit="Angstrom", symmetry=False, cart=False, verbose=0)
    mf = scf.RHF(mol)
    mf.conv_tol = 1e-10
    energy = mf.kernel()
    assert mf.converged, path
    text = io.StringIO()
    molden.header(mol, text)
    molden.orbital_coeff(mol, text, mf.mo_coeff, ene=mf.mo_energy, occ=mf.mo_occ)
    with open(path, "wb") as raw, gzip.GzipFile(fileobj=raw, mode="wb", compresslevel=9, mtime=0, filename="") as gz:
        gz.write(text.getvalue().encode())
    return energy


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--out", default="tests/fixtures/scans")
    out = Path(parser.parse_args().out)
    lib.num_threads(1)

    bend = out / "water_bend"
    bend.mkdir(parents=True, exist_ok=True)
    for angle in range(80, 161, 10):
        e = write_molden(bend / f"h2o_a{angle:03d}.molden.gz", water(angle, 0.96, 0.96), "6-31g")
        print(f"bend {angle:3d} deg: E = {e:.8f}")

    stretch = out / "water_stretch"
    stretch.mkdir(parents=True, exist_ok=True)
    for r in (0.80, 1.00, 1.20, 1.40, 1.60):
        e = write_molden(stretch / f"h2o_r{round(r * 100):03d}.molden.gz", stretched(r), "sto-3g")
        print(f"stretch {r:.2f} A: E = {e:.8f}")

    path = out / "water_path"
    path.mkdir(parents=True, exist_ok=True)
    steps = 4
    lines = [
        "# A morph in which the angle and a bond change together: no single coordinate.",
        'title = "water morph"',
        'coordinate = "path"',
        "align = false",
        'orbitals = ["homo", "lumo"]',
    ]
    for s in range(steps):
        t = s / (steps - 1)
        angle, r = 95 + 30 * t, 0.90 + 0.30 * t
        name = f"h2o_p{s}.molden.gz"
        e = write_molden(path / name, water(angle, 0.96, r), "sto-3g")
        lines += ["", "[[frame]]", f"at = {s}", f'file = "{name}"']
        print(f"path {s}: {angle:.1f} deg, {r:.2f} A: E = {e:.8f}")
    (path / "water_path.scan.toml").write_text("\n".join(lines) + "\n")
    assert np.isfinite(e)

    turned = out / "water_turned"
    turned.mkdir(parents=True, exist_ok=True)
    lines = [
        "# The morph of water_path/, each frame in its own orientation: aligned on reading.",
        'title = "water morph, turned"',
        'coordinate = "path"',
        "align = true",
        'orbitals = ["homo", "lumo"]',
    ]
    for s in range(steps):
        t = s / (steps - 1)
        atoms = water(95 + 30 * t, 0.96, 0.90 + 0.30 * t)
        if s > 0:
            atoms = moved(atoms, axis=[1.0, 2.0, 0.5 + s], degrees=40.0 * s, shift=[0.3 * s, -0.5, 1.0])
        name = f"h2o_t{s}.molden.gz"
        write_molden(turned / name, atoms, "sto-3g")
        lines += ["", "[[frame]]", f"at = {s}", f'file = "{name}"']
    (turned / "water_turned.scan.toml").write_text("\n".join(lines) + "\n")


def moved(atoms, axis, degrees, shift):
    """`atoms` turned by `degrees` about `axis` (through the origin), then shifted (A)."""
    a = np.asarray(axis, float) / np.linalg.norm(axis)
    th = math.radians(degrees)
    k = np.array([[0, -a[2], a[1]], [a[2], 0, -a[0]], [-a[1], a[0], 0]])
    r = np.eye(3) + math.sin(th) * k + (1 - math.cos(th)) * k @ k
    return [(sym, tuple(r @ np.asarray(p) + np.asarray(shift))) for sym, p in atoms]


if __name__ == "__main__":
    main()
