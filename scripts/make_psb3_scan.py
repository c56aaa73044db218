#!/usr/bin/env python3
"""Generate the PSB3 torsion scan, assets/psb3/: 15 gzipped Molden files and a scan manifest.

    OMP_NUM_THREADS=2 python3 scripts/make_psb3_scan.py [--out assets/psb3]

(PySCF, numpy and geomeTRIC; see scripts/requirements.txt. About 4 minutes on 2 cores.)

PSB3, the retinal model protonated Schiff base H2C=CH-CH=CH-CH=NH2+ (charge +1, singlet,
14 atoms), in the atom order C1 C2 C3 C4 C5 N, then H1a H1b (on C1), H2, H3, H4, H5 (on C2..C5),
HNa HNb (on N), so that the central dihedral C2-C3-C4-C5 is atoms 2 3 4 5 (1-based).

1. A planar all-trans guess is optimised at RHF/6-31G* (pure d) with geomeTRIC through
   pyscf.geomopt (GAU_TIGHT criteria). The minimum is then moved rigidly so that the C3-C4
   midpoint is at the origin, C3->C4 points along +x and the molecular plane is the xy plane
   (the viewer's default camera looks along -z), flattened onto z = 0 and rounded to 1e-6 A.
2. Rigid scan: the C4 half (H4, C5, H5, N, HNa, HNb; C4 itself lies on the axis) is rotated
   about the C3-C4 axis so that the dihedral C2-C3-C4-C5 takes the 15 angles of ANGLES
   (-180 = the planar trans minimum, 0 = cis); every measured dihedral is checked to 1e-6
   degrees and every intra-fragment distance to 1e-9 Angstrom.
3. Each geometry: single-point RHF/6-31G*, symmetry off, pure d, conv_tol 1e-10, the default
   MINAO initial guess (deterministic; no guess carried between frames), on one thread. The Molden file holds
   the full basis but only the orbital window HOMO-3 .. LUMO+3 (8 MOs, energies and
   occupations; symmetry label "A"); orbital signs are the solver's, not adjusted, so the
   files exercise a reader's sign alignment. Files: psb3_m180.molden.gz .. psb3_000.molden.gz
   ("m" = minus, three digits), gzip level 9 with no name and mtime 0.
4. psb3.scan.toml lists the frames (paths relative to the manifest).
5. A summary goes to stdout: energies, HOMO/LUMO sign flips between neighbouring frames from
   <psi_prev|psi_cur> with the cross-geometry AO overlap (gto.intor_cross), the best match of
   each HOMO/LUMO among the previous frame's window, RHF stability, and the fraction of the
   HOMO and LUMO on the C=N side (Mulliken and Lowdin orbital populations).

The output is byte-identical from run to run on a given machine: the optimised minimum is
rounded to 1e-6 A and the single points run on one thread (with two, OpenMP reductions change
the last printed digits). Orbital signs come straight from the eigensolver, so another BLAS
may flip some of them.
"""

from __future__ import annotations

import argparse
import contextlib
import gzip
import io
import os
import sys
import time
from pathlib import Path

import numpy as np
import pyscf
from pyscf import gto, lib, scf

BASIS = "6-31G*"
CHARGE = 1
ANGLES = [-180, -150, -120, -110, -105, -100, -95, -90, -85, -80, -75, -70, -60, -30, 0]
WINDOW_BELOW = 3  # HOMO-3 ..
WINDOW_ABOVE = 3  # .. LUMO+3
MAX_TOTAL_BYTES = 1_000_000

SYMBOLS = ["C", "C", "C", "C", "C", "N", "H", "H", "H", "H", "H", "H", "H", "H"]
LABELS = ["C1", "C2", "C3", "C4", "C5", "N", "H1a", "H1b", "H2", "H3", "H4", "H5", "HNa", "HNb"]
DIHEDRAL = (1, 2, 3, 4)  # 0-based C2 C3 C4 C5
AXIS = (2, 3)  # C3 -> C4
MOVING = [4, 5, 10, 11, 12, 13]  # C5, N, H4, H5, HNa, HNb (C4 is on the axis)
C4 = 3
ALLYL = [0, 1, 2, 6, 7, 8, 9]  # C1 C2 C3 and their hydrogens


def guess_geometry() -> np.ndarray:
    """Planar all-trans PSB3 (Angstrom), 120 degree angles, typical bond lengths, in the xy plane."""
    backbone = [1.35, 1.44, 1.36, 1.42, 1.30]  # C1=C2, C2-C3, C3=C4, C4-C5, C5=N
    xyz = np.zeros((14, 3))
    for k, r in enumerate(backbone):
        a = np.deg2rad(30.0 if k % 2 == 0 else -30.0)  # zigzag: all-trans
        xyz[k + 1] = xyz[k] + r * np.array([np.cos(a), np.sin(a), 0.0])

    def rot2(v, deg):
        c, s = np.cos(np.deg2rad(deg)), np.sin(np.deg2rad(deg))
        return np.array([c * v[0] - s * v[1], s * v[0] + c * v[1], 0.0])

    def unit(v):
        return v / np.linalg.norm(v)

    # Terminal CH2 and NH2: two H at +-120 degrees from the bond to the neighbour.
    u = unit(xyz[1] - xyz[0])
    xyz[6] = xyz[0] + 1.08 * rot2(u, 120.0)
    xyz[7] = xyz[0] + 1.08 * rot2(u, -120.0)
    u = unit(xyz[4] - xyz[5])
    xyz[12] = xyz[5] + 1.01 * rot2(u, 120.0)
    xyz[13] = xyz[5] + 1.01 * rot2(u, -120.0)
    # CH on C2..C5: along the outer bisector.
    for k, h in zip(range(1, 5), range(8, 12)):
        b = unit(xyz[k - 1] - xyz[k]) + unit(xyz[k + 1] - xyz[k])
        xyz[h] = xyz[k] - 1.08 * unit(b)
    return xyz


def build_mol(xyz: np.ndarray) -> gto.Mole:
    return gto.M(atom=[(s, tuple(float(c) for c in p)) for s, p in zip(SYMBOLS, xyz)],
                 unit="Angstrom", basis=BASIS, charge=CHARGE, spin=0, symmetry=False,
                 cart=False, verbose=0)


def run_rhf(mol: gto.Mole) -> scf.hf.RHF:
    mf = scf.RHF(mol)
    mf.conv_tol = 1e-10
    mf.conv_tol_grad = 1e-6
    mf.max_cycle = 200
    mf.init_guess = "minao"
    mf.kernel()
    if not mf.converged:
        raise RuntimeError("RHF did not converge")
    return mf


def dihedral(xyz: np.ndarray, idx) -> float:
    """IUPAC signed dihedral a-b-c-d in degrees, in (-180, 180]."""
    a, b, c, d = (xyz[i] for i in idx)
    b1, b2, b3 = b - a, c - b, d - c
    n1, n2 = np.cross(b1, b2), np.cross(b2, b3)
    x = np.dot(n1, n2)
    y = np.dot(np.cross(n1, n2), b2 / np.linalg.norm(b2))
    return float(np.degrees(np.arctan2(y, x)))


def wrap(deg: float) -> float:
    """Angle difference wrapped into (-180, 180]."""
    return float(-((-deg + 180.0) % 360.0 - 180.0))


def rotate_about(points: np.ndarray, origin: np.ndarray, axis: np.ndarray, deg: float) -> np.ndarray:
    """Rodrigues rotation of points by deg (right-handed) about the line origin + t*axis."""
    k = axis / np.linalg.norm(axis)
    t = np.deg2rad(deg)
    v = points - origin
    rot = (v * np.cos(t) + np.cross(k, v) * np.sin(t)
           + np.outer(v @ k, k) * (1.0 - np.cos(t)))
    return origin + rot


def optimise(xyz0: np.ndarray) -> np.ndarray:
    from pyscf.geomopt.geometric_solver import optimize

    mf = scf.RHF(build_mol(xyz0))
    mf.conv_tol = 1e-10
    log = io.StringIO()
    with contextlib.redirect_stdout(log), contextlib.redirect_stderr(log):
        mol = optimize(mf, maxsteps=100, convergence_set="GAU_TIGHT")
    return mol.atom_coords(unit="Angstrom")


def standard_frame(xyz: np.ndarray) -> np.ndarray:
    """C3-C4 midpoint at the origin, C3->C4 along +x, best molecular plane = xy, C1 at y > 0."""
    xyz = xyz - 0.5 * (xyz[AXIS[0]] + xyz[AXIS[1]])
    ex = xyz[AXIS[1]] - xyz[AXIS[0]]
    ex /= np.linalg.norm(ex)
    centred = xyz - xyz.mean(0)
    normal = np.linalg.svd(centred)[2][2]
    ez = normal - np.dot(normal, ex) * ex
    ez /= np.linalg.norm(ez)
    ey = np.cross(ez, ex)
    out = xyz @ np.array([ex, ey, ez]).T
    if out[0, 1] < 0:  # C1 on +y (a proper rotation by 180 degrees about x)
        out[:, 1:] *= -1.0
    return out


def scan_geometry(xyz_min: np.ndarray, target: float) -> np.ndarray:
    phi0 = dihedral(xyz_min, DIHEDRAL)
    xyz = xyz_min.copy()
    xyz[MOVING] = rotate_about(xyz_min[MOVING], xyz_min[AXIS[1]],
                               xyz_min[AXIS[1]] - xyz_min[AXIS[0]], wrap(target - phi0))
    got = dihedral(xyz, DIHEDRAL)
    assert abs(wrap(got - target)) < 1e-6, (target, got)
    # Rigid: distances inside each half unchanged.
    fixed = [i for i in range(len(xyz)) if i not in MOVING]
    for grp in (MOVING + [C4], fixed):
        d0 = np.linalg.norm(xyz_min[grp][:, None] - xyz_min[grp][None], axis=-1)
        d1 = np.linalg.norm(xyz[grp][:, None] - xyz[grp][None], axis=-1)
        assert np.abs(d0 - d1).max() < 1e-9
    return xyz


def orbital_populations(mol, s, c):
    """Mulliken and Lowdin atomic populations of one orbital (each sums to 1)."""
    mull_ao = c * (s @ c)
    w, v = np.linalg.eigh(s)
    s_half = (v * np.sqrt(w)) @ v.T
    low_ao = (s_half @ c) ** 2
    atom_of_ao = np.zeros(mol.nao_nr(), dtype=int)
    for ia, (_, _, p0, p1) in enumerate(mol.offset_nr_by_atom()):
        atom_of_ao[p0:p1] = ia
    mull = np.bincount(atom_of_ao, mull_ao, minlength=mol.natm)
    low = np.bincount(atom_of_ao, low_ao, minlength=mol.natm)
    return mull, low


def write_molden_gz(path: Path, mol, mf, lo: int, hi: int) -> int:
    from pyscf.tools import molden

    buf = io.StringIO()
    molden.header(mol, buf)
    molden.orbital_coeff(mol, buf, mf.mo_coeff[:, lo:hi], ene=mf.mo_energy[lo:hi],
                         occ=mf.mo_occ[lo:hi])
    data = gzip.compress(buf.getvalue().encode("ascii"), compresslevel=9, mtime=0)
    path.write_bytes(data)
    return len(data)


def stem(angle: int) -> str:
    return "psb3_%s%03d" % ("m" if angle < 0 else "", abs(angle))


def write_manifest(path: Path) -> None:
    lines = [
        "# PSB3 cation, RHF/6-31G*, rigid rotation about the central C=C "
        "(written by scripts/make_psb3_scan.py)",
        'title = "PSB3 cation: twist about C3=C4, RHF/6-31G*"',
        "dihedral = [%s]" % ", ".join(str(i + 1) for i in DIHEDRAL),
        'orbitals = ["homo", "lumo"]',
    ]
    for a in ANGLES:
        lines += ["", "[[frame]]", "angle = %.1f" % a, 'file = "%s.molden.gz"' % stem(a)]
    path.write_text("\n".join(lines) + "\n")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", type=Path,
                    default=Path(__file__).resolve().parent.parent / "assets" / "psb3")
    args = ap.parse_args()
    args.out.mkdir(parents=True, exist_ok=True)
    t0 = time.time()
    print("PySCF %s, numpy %s, %d threads" % (pyscf.__version__, np.__version__, lib.num_threads()))

    # 1. Optimised planar trans minimum.
    import geometric
    xyz_min = standard_frame(optimise(guess_geometry()))
    print("  max |z| out of the xy plane after optimisation: %.2e A (then set to 0)"
          % np.abs(xyz_min[:, 2]).max())
    # Multithreaded integrals make the optimiser's last bits vary from run to run: flatten
    # (the minimum is planar) and round to 1e-6 A (+ 0.0 turns -0.0 into 0.0), so the scan
    # geometries, and with one thread the SCF and the files, are the same on every run.
    xyz_min[:, 2] = 0.0
    xyz_min = np.round(xyz_min, 6) + 0.0
    mol_min = build_mol(xyz_min)
    print("geomeTRIC %s: RHF/%s minimum (%.0f s)" % (geometric.__version__, BASIS, time.time() - t0))
    for name, idx in [("C1-C2-C3-C4", (0, 1, 2, 3)), ("C2-C3-C4-C5", DIHEDRAL),
                      ("C3-C4-C5-N", (2, 3, 4, 5)), ("H3-C3-C4-H4", (9, 2, 3, 10)),
                      ("H1a-C1-C2-C3", (6, 0, 1, 2)), ("C4-C5-N-HNa", (3, 4, 5, 12))]:
        print("  dihedral %-13s %12.6f" % (name, dihedral(xyz_min, idx)))
    bonds = [(0, 1), (1, 2), (2, 3), (3, 4), (4, 5)]
    print("  backbone bonds (A): " + "  ".join(
        "%s-%s %.4f" % (LABELS[i], LABELS[j], np.linalg.norm(xyz_min[i] - xyz_min[j]))
        for i, j in bonds))
    print("  Cartesian coordinates (A):")
    for lab, p in zip(LABELS, xyz_min):
        print("    %-4s %12.6f %12.6f %12.6f" % (lab, *p))

    # 2.-3. Scan.
    frames = []
    for a in ANGLES:
        xyz = scan_geometry(xyz_min, float(a))
        mol = build_mol(xyz)
        with lib.with_omp_threads(1):  # bit-reproducible SCF (2 threads: last digits vary)
            mf = run_rhf(mol)
        homo = int(np.where(mf.mo_occ > 0)[0].max())
        lumo = homo + 1
        lo, hi = homo - WINDOW_BELOW, lumo + WINDOW_ABOVE + 1
        size = write_molden_gz(args.out / (stem(a) + ".molden.gz"), mol, mf, lo, hi)
        _, _, stable_i, stable_e = mf.stability(internal=True, external=True, return_status=True)
        frames.append(dict(angle=a, mol=mol, mf=mf, homo=homo, lumo=lumo, lo=lo, hi=hi, size=size,
                           dihedral=dihedral(xyz, DIHEDRAL), stable_i=stable_i, stable_e=stable_e))
        print("  %5d: E = %.10f  dihedral %.9f  cycles %s  %d B (%.0f s)"
              % (a, mf.e_tot, frames[-1]["dihedral"], mf.cycles, size, time.time() - t0))
    write_manifest(args.out / "psb3.scan.toml")

    # 5. Summary.
    names = ["H-3", "H-2", "H-1", "HOMO", "LUMO", "L+1", "L+2", "L+3"]
    print()
    print("angle   E_tot (Eh)        E_HOMO     E_LUMO     gap      <H|H>prev  <L|L>prev  "
          "flipH flipL  HOMO: best |<prev|.>| (2nd)  LUMO: best (2nd)")
    flips_h = flips_l = 0
    for i, f in enumerate(frames):
        e = f["mf"].mo_energy
        row = "%5d  %.10f  %9.6f  %9.6f  %7.5f" % (f["angle"], f["mf"].e_tot, e[f["homo"]],
                                                 e[f["lumo"]], e[f["lumo"]] - e[f["homo"]])
        if i > 0:
            p = frames[i - 1]
            sx = gto.intor_cross("int1e_ovlp", p["mol"], f["mol"])
            cp = p["mf"].mo_coeff[:, p["lo"]:p["hi"]]
            cc = f["mf"].mo_coeff[:, f["lo"]:f["hi"]]
            ov = cp.T @ sx @ cc  # prev window x current window
            kh, kl = WINDOW_BELOW, WINDOW_BELOW + 1
            oh, ol = ov[kh, kh], ov[kl, kl]
            fh, fl = oh < 0, ol < 0
            flips_h += fh
            flips_l += fl
            # Best and runner-up match of the current HOMO / LUMO among the previous window.
            rh, rl = np.argsort(-np.abs(ov[:, kh]))[:2], np.argsort(-np.abs(ov[:, kl]))[:2]
            row += "  %+8.4f  %+8.4f    %-5s %-5s  %-4s %.4f (%-4s %.4f)  %-4s %.4f (%-4s %.4f)" % (
                oh, ol, "yes" if fh else "no", "yes" if fl else "no",
                names[rh[0]], abs(ov[rh[0], kh]), names[rh[1]], abs(ov[rh[1], kh]),
                names[rl[0]], abs(ov[rl[0], kl]), names[rl[1]], abs(ov[rl[1], kl]))
            f["ov"] = ov
        print(row)
    n = len(frames) - 1
    print("sign flips between neighbouring frames: HOMO %d of %d, LUMO %d of %d" % (flips_h, n, flips_l, n))
    for kind, key in (("internal (RHF->RHF)", "stable_i"), ("external (RHF->UHF)", "stable_e")):
        print("RHF stability, %s: %s" % (kind, ", ".join(
            "%d %s" % (f["angle"], "ok" if f[key] else "UNSTABLE") for f in frames)))

    print()
    print("fraction of |psi|^2 on the C=N side (C4..N half incl. C4; Mulliken / Lowdin), per frame:")
    print("angle   HOMO C=N side       LUMO allyl side     [HOMO: moving atoms, C4 | LUMO: moving, C4]")
    for f in frames:
        mol, mf = f["mol"], f["mf"]
        s = mol.intor("int1e_ovlp")
        out = []
        for k in (f["homo"], f["lumo"]):
            mull, low = orbital_populations(mol, s, mf.mo_coeff[:, k])
            out.append((mull, low))
        (hm, hl), (lm, ll) = out
        cn = lambda q: q[MOVING].sum() + q[C4]
        al = lambda q: q[ALLYL].sum()
        print("%5d   %.3f / %.3f       %.3f / %.3f       [%.3f, %.3f | %.3f, %.3f] (Mulliken)"
              % (f["angle"], cn(hm), cn(hl), al(lm), al(ll), hm[MOVING].sum(), hm[C4],
                 lm[MOVING].sum(), lm[C4]))
        if f["angle"] == -90:
            f["pops"] = out
    f90 = next(f for f in frames if f["angle"] == -90)
    (hm, hl), (lm, ll) = f90["pops"]
    print()
    print("-90 degrees, per-atom populations of HOMO and LUMO (Mulliken, Lowdin):")
    for ia, lab in enumerate(LABELS):
        print("  %-4s HOMO %7.4f %7.4f   LUMO %7.4f %7.4f" % (lab, hm[ia], hl[ia], lm[ia], ll[ia]))
    for name, grp in [("moving (H4 C5 H5 N HNa HNb)", MOVING), ("C4", [C4]),
                      ("C=N side (moving + C4)", MOVING + [C4]), ("allyl (C1-C3 + H)", ALLYL)]:
        print("  %-28s HOMO %.4f / %.4f   LUMO %.4f / %.4f"
              % (name, hm[grp].sum(), hl[grp].sum(), lm[grp].sum(), ll[grp].sum()))

    sizes = {p.name: p.stat().st_size for p in sorted(args.out.iterdir())}
    total = sum(sizes.values())
    print()
    for name, size in sizes.items():
        print("  %-24s %7d B" % (name, size))
    print("  total %d B; %.0f s" % (total, time.time() - t0))
    assert total < MAX_TOTAL_BYTES, total


if __name__ == "__main__":
    main()
