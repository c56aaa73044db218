#!/usr/bin/env python3
"""Writes tests/fixtures/logs/h2o2_scan.log: a Gaussian relaxed scan of hydrogen peroxide's
H-O-O-H dihedral (`opt=modredundant`, `D 3 1 2 4 S 4 60.0`: 120 to 360 degrees in 4 steps of
60), in the layout Gaussian 09 writes, with PySCF's geometries and energies.

The layout was checked against cclib's regression files data/Gaussian/basicGaussian09/
dvb_scan_relaxed.log (Gaussian 09 D.01) and dvb_scan.log (A.02), read line by line: the route
between dashes, "Symbolic Z-matrix:", the echoed section "The following ModRedundant input
section has been read:" with the type letter Gaussian adds (`D 3 4 9 10 S 12 30.000`), then per
optimisation step a "Standard orientation:" table and its `SCF Done` line, "Step number N out
of a maximum of M on scan point P out of Q", and per point "Optimization completed." /
"-- Stationary point found."; at the end "Summary of Optimized Potential Surface Scan" with the
energies in blocks of five (`Eigenvalues --`) and the dihedral wrapped to (-180, 180] as
Gaussian prints it (210 degrees as -150). Nothing is copied from those files: the molecule,
numbers and spacing here are this script's.

Each point is two steps: the start (the previous point's O-O length, the dihedral set) and the
converged geometry (the O-O length that minimises the RHF/STO-3G energy at that dihedral, by a
parabola through three lengths). The dihedral is set by turning the second hydrogen about the
O-O bond, so it is exact in every geometry; a reader measures it there.

It also writes tests/fixtures/scan_jobs/h2o2_relaxed_scan.fchk, the formatted checkpoint of the
same job: the last point's geometry and RHF/STO-3G orbitals (scripts/make_wavefunction_fixtures.py's
fchk writer), then the records a relaxed scan adds, one set per point: "Opt point N Results for
each geome" (two values a step, "Optimization Num results per geometry" = 2: the energy, then the
dihedral in degrees, which readers do not use) and "Opt point N Geometries" (every step, bohr).
cclib's water-pes.fchk (a rigid Z-matrix scan) holds none of these records, only the last
point's geometry and orbitals; the per-point layout follows what readers of Gaussian's relaxed-scan
checkpoints take from it (one "Opt point N" pair per scan point, the converged step last).

It also writes tests/fixtures/logs/h2o2_scan_orca.out: the same scan as ORCA runs it
(`! HF STO-3G Opt` with `%geom Scan D 2 0 1 3 = 120, 360, 5 end end`: atoms from 0, the first and
last value and the number of points), in the layout of cclib's regression file
data/ORCA/basicORCA6.0/dvb_scan_relaxed.out (ORCA 6.0.1; cclib commit
21daa960123d28aa21eeaaacc2a1dea39e136829, file at a2b0886a669d4f01d092b638fb6ce44de58cc083),
read part by part: the banner, "INPUT FILE" with the input echoed as `| 10> D 9 8 3 2 = 0, 360,
12`, the "Relaxed Surface Scan" box with `Dihedral (  9,   8,   3,   2):   range= ... steps =
12`, then per point a box "RELAXED SURFACE SCAN STEP   n" naming the value, per optimisation
cycle a box "GEOMETRY OPTIMIZATION CYCLE   k" with "CARTESIAN COORDINATES (ANGSTROEM)", "CARTESIAN
COORDINATES (A.U.)" (`NO LB ZA FRAG MASS X Y Z`) and "FINAL SINGLE POINT ENERGY", the "Geometry
convergence" table, "THE OPTIMIZATION HAS CONVERGED" in its HURRAY box, "FINAL ENERGY EVALUATION
AT THE STATIONARY POINT" with the coordinates and energy once more, "*** OPTIMIZATION RUN DONE
***" and "Storing optimized geometry in NAME.00n.xyz"; at the end "**** RELAXED SURFACE SCAN
DONE ***", "RELAXED SURFACE SCAN RESULTS", "Column   1: NONAME", "The Calculated Surface using
the 'Actual Energy'" and "... using the SCF energy" (`%13.8f %13.8f` rows: the value as
requested, 0 to 360 in 12 points there, and the energy) and "****ORCA TERMINATED NORMALLY****".
The SCF, gradient and property sections between them, which the reader skips, are left out;
nothing is copied from that file: the molecule, numbers and spacing here are this script's.

Run:   python3 scripts/make_scan_log_fixtures.py   (PySCF, numpy; a few seconds)
       python3 scripts/make_scan_log_fixtures.py orca   (the ORCA output only)
"""
import sys
from pathlib import Path

import numpy as np
from pyscf import gto, scf

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))
import make_wavefunction_fixtures as fx  # noqa: E402

OUT = HERE.parent / "tests" / "fixtures" / "logs" / "h2o2_scan.log"
FCHK = HERE.parent / "tests" / "fixtures" / "scan_jobs" / "h2o2_relaxed_scan.fchk"
ORCA = HERE.parent / "tests" / "fixtures" / "logs" / "h2o2_scan_orca.out"
BOHR = 0.52917721090380
START, STEPS, SIZE = 120.0, 4, 60.0
OH, OOH = 0.97, 100.0  # Å, degrees: fixed in this fixture


def geometry(oo: float, dihedral: float) -> np.ndarray:
    """O1, O2, H3 (on O1), H4 (on O2) in Å, H3-O1-O2-H4 = dihedral."""
    o1 = np.array([0.0, 0.0, 0.0])
    o2 = np.array([0.0, 0.0, oo])
    a = np.radians(OOH)
    h3 = o1 + OH * np.array([np.sin(a), 0.0, np.cos(a)])
    d = np.radians(dihedral)
    h4 = o2 + OH * np.array([np.sin(a) * np.cos(d), np.sin(a) * np.sin(d), -np.cos(a)])
    return np.array([o1, o2, h3, h4])


def molecule(xyz: np.ndarray):
    return gto.M(atom=[(s, p) for s, p in zip("OOHH", xyz)], basis="sto-3g", unit="Angstrom", verbose=0)


def energy(xyz: np.ndarray) -> float:
    return scf.RHF(molecule(xyz)).run(conv_tol=1e-10).e_tot


def best_oo(dihedral: float) -> float:
    """The O-O length at the minimum of a parabola through three lengths."""
    xs = np.array([1.34, 1.40, 1.46])
    es = np.array([energy(geometry(x, dihedral)) for x in xs])
    c = np.polyfit(xs, es, 2)
    return float(-c[1] / (2 * c[0]))


def orientation(xyz: np.ndarray) -> str:
    rule = " " + "-" * 69 + "\n"
    s = "                         Standard orientation:                         \n" + rule
    s += " Center     Atomic      Atomic             Coordinates (Angstroms)\n"
    s += " Number     Number       Type             X           Y           Z\n" + rule
    for k, (z, p) in enumerate(zip([8, 8, 1, 1], xyz)):
        s += "%7d%11d%12d    %12.6f%12.6f%12.6f\n" % (k + 1, z, 0, *p)
    return s + rule


def scf_done(e: float) -> str:
    return " SCF Done:  E(RHF) =  %.12f     A.U. after    8 cycles\n" % e


def main() -> None:
    s = " Entering Gaussian System, Link 0=g09\n"
    s += " ******************************************\n Gaussian 09:  ES64L-G09RevD.01 24-Apr-2013\n"
    s += " ******************************************\n"
    s += " ---------------------------------\n #p hf/sto-3g opt=modredundant\n ---------------------------------\n"
    s += " ----------------------\n H2O2 dihedral scan\n ----------------------\n"
    s += " Symbolic Z-matrix:\n Charge =  0 Multiplicity = 1\n"
    for sym, p in zip("OOHH", geometry(1.40, START)):
        s += " %-20s%10.5f%10.5f%10.5f \n" % (sym, *p)
    s += " \n The following ModRedundant input section has been read:\n"
    s += " D       3       1       2       4 S   %d %.3f" % (STEPS, SIZE) + " " * 32 + "\n"
    s += " \n"
    points = STEPS + 1
    oo = 1.40
    summary = []
    history = []  # per point: every step's (xyz, energy, dihedral)
    for p in range(points):
        dihedral = START + p * SIZE
        steps = [(oo, dihedral)]
        oo = best_oo(dihedral)
        steps.append((oo, dihedral))
        history.append([])
        for n, (x, d) in enumerate(steps):
            xyz = geometry(x, d)
            e = energy(xyz)
            history[-1].append((xyz, e, d))
            s += orientation(xyz)
            s += scf_done(e)
            s += "\n GradGradGradGradGradGradGradGradGradGradGradGradGradGradGradGradGradGrad\n"
            s += " Berny optimization.\n"
            s += " Step number %3d out of a maximum of   20 on scan point %5d out of %5d\n" % (n + 1, p + 1, points)
        s += " Optimization completed.\n    -- Stationary point found.\n"
        summary.append((e, x, d))
    s += "\n Summary of Optimized Potential Surface Scan\n"
    for first in range(0, points, 5):
        block = summary[first:first + 5]
        s += "           " + "".join("%10d" % (first + k + 1) for k in range(len(block))) + "\n"
        s += "     Eigenvalues -- " + "".join("%10.5f" % e for e, _, _ in block) + "\n"
        s += "           R1     " + "".join("%10.5f" % x for _, x, _ in block) + "\n"
        wrapped = [((d + 180.0) % 360.0) - 180.0 if ((d + 180.0) % 360.0) != 0.0 else 180.0 for _, _, d in block]
        s += "           D1     " + "".join("%10.5f" % d for d in wrapped) + "\n"
    s += " Normal termination of Gaussian 09.\n"
    OUT.write_text(s)
    print(OUT)
    write_fchk(history)


def write_fchk(history) -> None:
    """The job's checkpoint: the last point's orbitals, every point's steps."""
    xyz = history[-1][-1][0]
    mol = molecule(xyz)
    mf = scf.RHF(mol).run(conv_tol=1e-10)
    FCHK.parent.mkdir(parents=True, exist_ok=True)
    fx.write_fchk(str(FCHK), "H2O2 dihedral scan", "RHF", "STO-3G", mol, mf, mol.nao)
    lines = FCHK.read_text().splitlines()
    lines[1] = "Scan" + lines[1][4:] if lines[1].startswith("SP  ") else lines[1]
    f = fx.Fchk()
    f.int("Optimization Num results per geometry", 2)
    f.int("Optimization Num geometry variables", 3 * mol.natm)
    f.ints("Optimization Number of geometries", [len(point) for point in history])
    for k, point in enumerate(history):
        f.reals("Opt point %7d Results for each geome" % (k + 1), [v for _, e, d in point for v in (e, d)])
        f.reals("Opt point %7d Geometries" % (k + 1), np.concatenate([g for g, _, _ in point]) / BOHR)
    FCHK.write_text("\n".join(lines + f.lines) + "\n")
    print(FCHK)


STAR = "         " + "*" * 61 + "\n"


def box(*rows: str) -> str:
    """ORCA's boxes: 61 stars wide, each row between `*`s."""
    return STAR + "".join("         *" + r.ljust(59) + "*\n" for r in rows) + STAR


def orca_coordinates(xyz: np.ndarray) -> str:
    s = "---------------------------------\nCARTESIAN COORDINATES (ANGSTROEM)\n---------------------------------\n"
    for sym, p in zip("OOHH", xyz):
        s += "  %-2s %12.6f%12.6f%12.6f\n" % (sym, *p)
    s += "\n----------------------------\nCARTESIAN COORDINATES (A.U.)\n----------------------------\n"
    s += "  NO LB      ZA    FRAG     MASS         X           Y           Z\n"
    for k, (sym, p) in enumerate(zip("OOHH", xyz)):
        za, mass = (8.0, 15.999) if sym == "O" else (1.0, 1.008)
        s += "%4d %-2s%10.4f%5d%10.3f%12.6f%12.6f%12.6f\n" % (k, sym, za, 0, mass, *(p / BOHR))
    return s + "\n"


def orca_energy(e: float) -> str:
    rule = "-------------------------   --------------------\n"
    return "\n" + rule + "FINAL SINGLE POINT ENERGY %22.12f\n" % e + rule + "\n"


def convergence(converged: bool) -> str:
    flag = "YES" if converged else "NO"
    s = "                                .--------------------.\n"
    s += "          ----------------------|Geometry convergence|-------------------------\n"
    s += "          Item                value                   Tolerance       Converged\n"
    s += "          " + "-" * 69 + "\n"
    for item, tol in (("RMS gradient", 1e-4), ("MAX gradient", 3e-4), ("RMS step", 2e-3), ("MAX step", 4e-3)):
        s += "          %-18s%13.10f%19.10f      %s\n" % (item, tol / 2 if converged else tol * 20, tol, flag)
    s += "          " + "-" * 69 + "\n\n"
    if converged:
        s += "                    ***********************HURRAY********************\n"
        s += "                    ***        THE OPTIMIZATION HAS CONVERGED     ***\n"
        s += "                    *************************************************\n\n"
    else:
        s += "The optimization has not yet converged - more geometry cycles are needed\n\n"
    return s


def write_orca() -> None:
    """The scan as ORCA 6 prints it: two cycles a point (the start, then the converged O-O
    length) and the final evaluation at the converged geometry."""
    name = "h2o2_scan"
    points = STEPS + 1
    last = START + STEPS * SIZE
    lines = ["! HF STO-3G Opt", "", "%geom Scan", "D 2 0 1 3 = %g, %g, %d" % (START, last, points), "end", "end", "",
             "* xyz 0 1"]
    lines += ["%-2s %12.5f %12.5f %12.5f" % (sym, *p) for sym, p in zip("OOHH", geometry(1.40, START))]
    lines += ["*", ""]
    s = "\n                                 *****************\n"
    s += "                                 * O   R   C   A *\n"
    s += "                                 *****************\n\n"
    s += "                         Program Version 6.0.1  -  RELEASE   -\n\n"
    s += "=" * 80 + "\n" + " " * 39 + "INPUT FILE\n" + "=" * 80 + "\n"
    s += "NAME = %s.inp\n" % name
    for k, text in enumerate(lines):
        s += "|%3d> %s\n" % (k + 1, text)
    s += "|%3d>                          ****END OF INPUT****\n" % (len(lines) + 1)
    s += "=" * 80 + "\n\n"
    s += "                       ******************************\n"
    s += "                       *    Relaxed Surface Scan    *\n"
    s += "                       ******************************\n\n"
    atoms = "(  2,   0,   1,   3)"
    s += "        Dihedral %s:   range= %12.8f .. %12.8f  steps = %4d\n\n" % (atoms, START, last, points)
    s += "There is 1 parameter to be scanned.\n"
    s += "There will be %4d constrained geometry optimizations.\n\n\n" % points
    oo = 1.40
    table = []
    for p in range(points):
        dihedral = START + p * SIZE
        s += box(" " * 15 + "RELAXED SURFACE SCAN STEP %3d" % (p + 1), "", "   Dihedral %s  : %12.8f" % (atoms, dihedral))
        s += "\nGeometry optimization settings:\nUpdate method            Update   .... BFGS\n\n"
        cycles = [oo]
        oo = best_oo(dihedral)
        cycles.append(oo)
        for c, x in enumerate(cycles):
            xyz = geometry(x, dihedral)
            e = energy(xyz)
            s += "\n" + box(" " * 16 + "GEOMETRY OPTIMIZATION CYCLE %3d" % (c + 1))
            s += orca_coordinates(xyz) + orca_energy(e) + convergence(c + 1 == len(cycles))
        s += "                 " + "*" * 55 + "\n"
        s += "                 *** FINAL ENERGY EVALUATION AT THE STATIONARY POINT ***\n"
        s += "                 ***               (AFTER %4d CYCLES)               ***\n" % len(cycles)
        s += "                 " + "*" * 55 + "\n"
        xyz = geometry(oo, dihedral)
        e = energy(xyz)
        s += orca_coordinates(xyz) + orca_energy(e)
        s += "                                *** OPTIMIZATION RUN DONE ***\n\n\n"
        s += "Storing optimized geometry in %s.%03d.xyz ... done\n" % (name, p + 1)
        s += "Storing optimized geometry and energy in %s.xyzall ... done\n\n" % name
        table.append((dihedral, e))
    s += "                   **** RELAXED SURFACE SCAN DONE ***\n\n"
    s += "                    SUMMARY OF THE CALCULATED SURFACE\n\n"
    s += "----------------------------\nRELAXED SURFACE SCAN RESULTS\n----------------------------\n\n"
    s += "Column   1: NONAME\n\n"
    for what in ("the 'Actual Energy'", "the SCF energy"):
        s += "The Calculated Surface using %s\n" % what
        s += "".join("%13.8f %13.8f\n" % row for row in table) + "\n"
    s += "\n                             ****ORCA TERMINATED NORMALLY****\n"
    ORCA.write_text(s)
    print(ORCA)


if __name__ == "__main__":
    if sys.argv[1:] == ["orca"]:
        write_orca()
    else:
        main()
        write_orca()
