#!/usr/bin/env python3
"""Frequency-job fixtures in the layouts of GAMESS-US, NWChem, Psi4 and Q-Chem logs, computed
with PySCF: water (RHF/STO-3G, at the minimum geomeTRIC finds) in all four, and planar ammonia
(RHF/STO-3G, the inversion's transition state: one imaginary mode) in GAMESS-US's, Psi4's and
Q-Chem's, whose notations for an imaginary frequency differ.

    target/pyenv/bin/python scripts/make_log_mode_fixtures.py tests/fixtures/logs

writes `{molecule}_{program}_freq.out` and `{molecule}_freq.expected.json` (PySCF's values at full
precision: wavenumbers, IR intensities in km/mol, displacements normalised to Σ|d|² = 1, the
geometry in bohr).

Modes: PySCF's analytic Hessian and `pyscf.hessian.thermo.harmonic_analysis` with the masses of
the most abundant isotopes (as the four programs use). IR intensities: dipole derivatives by
central differences of the SCF dipole (±1e-3 bohr), dμ/dQ = Σ_i ∂μ/∂x_i · L_i/√m_i, intensity =
974.8801 km/mol per (e²/amu) · |dμ/dQ|² (GAMESS prints it in D²/(amu·Å²): ÷ 42.2561).

The layouts follow real frequency logs of the same kind (dvb, C10H10) in cclib's regression data,
github.com/cclib/cclib at commit 21daa960123d28aa21eeaaacc2a1dea39e136829, read column by column:

- GAMESS-US 2018 R3, data/GAMESS/basicGAMESS-US2018/dvb_ir.out and nh3_ts_ir.out: the coordinate
  table `ATOM ATOMIC COORDINATES (BOHR)`; `NORMAL COORDINATE ANALYSIS IN THE HARMONIC
  APPROXIMATION`, `ATOMIC WEIGHTS (AMU)`, `MODES i TO j ARE TAKEN AS ROTATIONS AND TRANSLATIONS.`,
  blocks of 5 modes (all 3N, sorted by eigenvalue, the rigid ones among them) headed `FREQUENCY:`
  (F10.2 and ` I` for an imaginary one), `SYMMETRY:`, `REDUCED MASS:`, `IR INTENSITY:`
  (D²/(amu·Å²)), rows `n  name  X|Y|Z` of F12.8 displacements normalised as Σ m·|d|² = 1, then the
  `TRANS. SAYVETZ` and `ROT. SAYVETZ` sums.
- NWChem 7.0.2, data/NWChem/basicNWChem7.0/dvb_ir.out: `Output coordinates in angstroms`; the last
  (projected) `NORMAL MODE EIGENVECTORS IN CARTESIAN COORDINATES`, blocks of 6 modes, `P.Frequency`
  (F12.2, rigid modes 0.00), one row per coordinate (F12.5, Σ m·|d|² = 1); `Projected Infra Red
  Intensities` (atomic units, (debye/angs)**2, KM/mol, arbitrary = 2.27712 × KM/mol as there).
- Psi4 1.7, data/Psi4/basicPsi4-1.7/dvb_ir_rhf.out: `Geometry (in Bohr)` with masses; `==> Harmonic
  Vibrational Analysis <==`, blocks of 3 vibrations (`Vibration`, `Freq [cm^-1]` with an `i` suffix
  when imaginary, `Irrep`, `Reduced mass [u]`, `Force const [mDyne/A]`, `Turning point v=0 [a0]`,
  `RMS dev v=0 [a0 u^1/2]`, `IR activ [km/mol]`, `Char temp [K]`, fields centred in 20 columns),
  dashes, rows `n  symbol  x y z …` (F6.2, Σ|d|² = 1). The run here is C1 (`Irrep` A); the
  diagnostic lines Psi4 prints between the heading and the first block (Hessian checks, the
  pre- and post-projection frequency lists) are left out.
- Q-Chem 5.4, data/QChem/basicQChem5.4/dvb_ir.out and water_ir.out: `Standard Nuclear Orientation
  (Angstroms)`; the `VIBRATIONAL ANALYSIS` banner, blocks of 3 vibrations `Mode:`, `Frequency:`
  (negative when imaginary), `Force Cnst:`, `Red. Mass:`, `IR Active:`, `IR Intens:` (km/mol),
  `Raman Active:`, the `X Y Z` heading, rows `symbol x y z …` (F7.3, Σ|d|² = 1), `TransDip`.
"""
import json
import os
import sys

import numpy as np
from pyscf import gto, scf
from pyscf.data.elements import COMMON_ISOTOPE_MASSES
from pyscf.geomopt.geometric_solver import optimize
from pyscf.hessian import thermo

ANGSTROM = 1.0 / 0.529177210903  # bohr per ångström (CODATA 2018, as orbcloud)
KM_PER_MOL_AU = 974.8801  # km/mol per (e²/amu)
KM_PER_MOL_DEBYE2 = 42.2561  # km/mol per D²/(amu·Å²)
NWCHEM_ARBITRARY = 2.27712  # NWChem's `arbitrary` column per km/mol (dvb_ir.out: 98.896 → 225.197)

MOLECULES = {
    # Starting geometries, optimised here (planar ammonia keeps its D3h symmetry: its gradient
    # has no out-of-plane component).
    "h2o": ("O 0 0 0.1239; H 0 0.7573 -0.4955; H 0 -0.7573 -0.4955", ["gamess", "nwchem", "psi4", "qchem"]),
    "nh3_planar": (
        "N 0 0 0; H 1.007 0 0; H -0.5035 0.872088 0; H -0.5035 -0.872088 0",
        ["gamess", "psi4", "qchem"],
    ),
}


def scf_of(atom):
    """RHF/STO-3G at the stationary point geomeTRIC finds from `atom`."""
    mol = gto.M(atom=atom, basis="sto-3g", unit="Angstrom", verbose=0)
    mf = scf.RHF(mol)
    mf.conv_tol = 1e-12
    mol = optimize(mf, convergence_set="GAU_VERYTIGHT")
    mf = scf.RHF(mol)
    mf.conv_tol = 1e-12
    mf.kernel()
    return mol, mf


def dipole_derivatives(mol, step=1e-3):
    """∂μ/∂x (a.u.), shape (3N, 3), by central differences of the SCF dipole."""
    coords = mol.atom_coords()
    out = []
    for a in range(mol.natm):
        for c in range(3):
            mu = []
            for s in (1, -1):
                x = coords.copy()
                x[a, c] += s * step
                m = mol.set_geom_(x, unit="Bohr", inplace=False)
                f = scf.RHF(m)
                f.conv_tol = 1e-12
                f.kernel()
                mu.append(f.dip_moment(unit="AU", verbose=0))
            out.append((mu[0] - mu[1]) / (2 * step))
    return np.array(out)


def analysis(atom):
    mol, mf = scf_of(atom)
    hess = mf.Hessian().kernel()
    mass = np.array([COMMON_ISOTOPE_MASSES[z] for z in mol.atom_charges()])
    res = thermo.harmonic_analysis(mol, hess, mass=mass, imaginary_freq=False)
    freq = np.asarray(res["freq_wavenumber"]).real
    modes = np.asarray(res["norm_mode"])  # L/√m per mode: Σ m·|d|² = 1
    dmu = dipole_derivatives(mol)
    dmu_dq = np.einsum("xk,ix->ik", dmu, modes.reshape(len(freq), -1))
    intensity = KM_PER_MOL_AU * (dmu_dq**2).sum(1)
    # The full 3N spectrum GAMESS and NWChem print: the vibrations and the translations and
    # rotations (an orthonormal basis of their mass-weighted space, the unprojected Hessian's
    # wavenumbers in it), sorted by eigenvalue.
    natm = mol.natm
    sq = np.sqrt(np.repeat(mass, 3))
    h_mw = hess.transpose(0, 2, 1, 3).reshape(3 * natm, 3 * natm) / np.outer(sq, sq)
    coords = mol.atom_coords()
    com = (mass[:, None] * coords).sum(0) / mass.sum()
    r = coords - com
    rigid = []
    for c in range(3):
        v = np.zeros((natm, 3))
        v[:, c] = 1
        rigid.append((v * np.sqrt(mass)[:, None]).ravel())
    for c in range(3):
        axis = np.eye(3)[c]
        v = np.cross(axis, r)
        rigid.append((v * np.sqrt(mass)[:, None]).ravel())
    q, _ = np.linalg.qr(np.array(rigid).T)
    w, u = np.linalg.eigh(q.T @ h_mw @ q)
    rigid_vec = (q @ u).T
    au2cm = freq[-1] / np.sqrt(res["force_const_au"][-1])
    rigid_freq = np.sign(w) * np.sqrt(np.abs(w)) * au2cm
    rigid_disp = rigid_vec.reshape(-1, natm, 3) / np.sqrt(mass)[None, :, None]
    return {
        "mol": mol,
        "mass": mass,
        "freq": freq,
        "disp": modes,
        "intensity": intensity,
        "reduced_mass": np.asarray(res["reduced_mass"]),
        "force_mdyne": np.asarray(res["force_const_dyne"]),
        "dmu_dq": dmu_dq,
        "rigid_freq": rigid_freq,
        "rigid_disp": rigid_disp,
    }


def symbols(mol):
    return [mol.atom_pure_symbol(a) for a in range(mol.natm)]


def everything(a):
    """All 3N modes sorted by eigenvalue (signed wavenumber): (frequency, displacement (Σ m d² =
    1), intensity km/mol, reduced mass, is rigid)."""
    rows = [(f, d, i, rm, False) for f, d, i, rm in zip(a["freq"], a["disp"], a["intensity"], a["reduced_mass"])]
    mass = a["mass"]
    for f, d in zip(a["rigid_freq"], a["rigid_disp"]):
        rm = 1.0 / (d**2).sum()
        rows.append((f, d, 0.0, rm, True))
    return sorted(rows, key=lambda r: r[0])


def unit(d):
    return d / np.sqrt((d**2).sum())


# ---- GAMESS-US ------------------------------------------------------------------------------


def gamess(a):
    mol = a["mol"]
    mass = a["mass"]
    out = []
    w = out.append
    w("          ******************************************************")
    w("          *         GAMESS VERSION = 30 SEP 2018 (R3)         *")
    w("          ******************************************************")
    w("")
    w(" ATOM      ATOMIC                      COORDINATES (BOHR)")
    w("           CHARGE         X                   Y                   Z")
    for s, z, p in zip(symbols(mol), mol.atom_charges(), mol.atom_coords()):
        w(f" {s:<10s}{z:5.1f}{p[0]:17.10f}{p[1]:20.10f}{p[2]:20.10f}")
    w("")
    w("          --------------------------------------------------------")
    w("          NORMAL COORDINATE ANALYSIS IN THE HARMONIC APPROXIMATION")
    w("          --------------------------------------------------------")
    w("")
    w("          ATOMIC WEIGHTS (AMU)")
    w("")
    for k, (s, m) in enumerate(zip(symbols(mol), mass)):
        w(f"{k + 1:5d}     {s:<2s}{m:23.5f}")
    w("")
    rows = everything(a)
    rigid = [k + 1 for k, r in enumerate(rows) if r[4]]
    if any(r[0] < 0 and not r[4] for r in rows):
        imaginary = [k + 1 for k, r in enumerate(rows) if r[0] < 0 and not r[4]]
        w(f" MODE(S) {imaginary[0]:5d} TO {imaginary[-1]:5d} TREATED AS IMAGINARY.")
        w("")
    w(f" MODES {rigid[0]:4d} TO {rigid[-1]:4d} ARE TAKEN AS ROTATIONS AND TRANSLATIONS.")
    w("")
    w(" ANALYZING SYMMETRY OF NORMAL MODES...")
    w("")
    w("     FREQUENCIES IN CM**-1, IR INTENSITIES IN DEBYE**2/AMU-ANGSTROM**2,")
    w("     REDUCED MASSES IN AMU.")
    w("")
    r = mol.atom_coords() - (mass[:, None] * mol.atom_coords()).sum(0) / mass.sum()
    for start in range(0, len(rows), 5):
        block = rows[start : start + 5]
        w(" " * 17 + "".join(f"{start + k + 1:12d}" for k in range(len(block))))
        w("       FREQUENCY:   " + "".join(f"{abs(b[0]):10.2f}" + (" I" if b[0] < 0 else "  ") for b in block))
        w("        SYMMETRY:" + "".join(f"{'A':>10s}  " for _ in block) + " ")
        w("    REDUCED MASS: " + "".join(f"{b[3]:12.5f}" for b in block))
        w("    IR INTENSITY: " + "".join(f"{b[2] / KM_PER_MOL_DEBYE2:12.5f}" for b in block))
        w("")
        for k, s in enumerate(symbols(mol)):
            for c, axis in enumerate("XYZ"):
                head = f"{k + 1:3d}   {s:<13s}{axis}" if c == 0 else " " * 19 + axis
                w(head + "".join(f"{b[1][k][c]:12.8f}" for b in block))
        w("")
        trans = np.array([(mass[:, None] * b[1]).sum(0) for b in block])
        rot = np.array([(mass[:, None] * np.cross(r, b[1])).sum(0) for b in block])
        for title, v in ((" TRANS. SAYVETZ    ", trans), ("   ROT. SAYVETZ    ", rot)):
            for c, axis in enumerate("XYZ"):
                w((title if c == 0 else " " * 19) + axis + "".join(f"{x[c]:12.8f}" for x in v))
            w("               TOTAL" + "".join(f"{np.linalg.norm(x):12.8f}" for x in v))
            w("")
    w(" REFERENCE ON SAYVETZ CONDITIONS - A. SAYVETZ, J.CHEM.PHYS., 7, 383-389(1939).")
    w("")
    w("              ......END OF NORMAL COORDINATE ANALYSIS......")
    return "\n".join(out) + "\n"


# ---- NWChem ---------------------------------------------------------------------------------


def nwchem_header(mol):
    """NWChem 7.0.2's banner and its geometry table (Å), as its logs begin; also used by
    make_nwchem_spherical_fixture.py."""
    out = [
        "              Northwest Computational Chemistry Package (NWChem) 7.0.2",
        "              --------------------------------------------------------",
        "",
        '                             Geometry "geometry" -> ""',
        "                             -------------------------",
        "",
        " Output coordinates in angstroms (scale by  1.889725989 to convert to a.u.)",
        "",
        "  No.       Tag          Charge          X              Y              Z",
        " ---- ---------------- ---------- -------------- -------------- --------------",
    ]
    for k, (s, z, p) in enumerate(zip(symbols(mol), mol.atom_charges(), mol.atom_coords() / ANGSTROM)):
        out.append(f"{k + 1:5d} {s:<16s}{z:11.4f}{p[0]:15.8f}{p[1]:15.8f}{p[2]:15.8f}")
    return out


def nwchem(a):
    mol = a["mol"]
    out = nwchem_header(mol)
    w = out.append
    w("")
    rows = everything(a)
    # Projected: the rigid modes' wavenumbers are zero.
    rows = [(0.0, d, i, rm, True) if rigid else (f, d, i, rm, rigid) for f, d, i, rm, rigid in rows]
    rows.sort(key=lambda r: r[0])
    w("")
    w("          -------------------------------------------------")
    w("          NORMAL MODE EIGENVECTORS IN CARTESIAN COORDINATES")
    w("          -------------------------------------------------")
    w("             (Projected Frequencies expressed in cm-1)")
    w("")
    for start in range(0, len(rows), 6):
        block = rows[start : start + 6]
        w(" " * 9 + "".join(f"{start + k + 1:12d}" for k in range(len(block))))
        w(" ")
        w(" P.Frequency" + "".join(f"{b[0]:12.2f}" for b in block))
        w(" ")
        for c in range(3 * mol.natm):
            w(f"{c + 1:12d}" + "".join(f"{b[1][c // 3][c % 3]:12.5f}" for b in block))
        w("")
    w("")
    w(" ----------------------------------------------------------------------------")
    w(" Normal Eigenvalue ||           Projected Infra Red Intensities")
    w("  Mode   [cm**-1]  || [atomic units] [(debye/angs)**2] [(KM/mol)] [arbitrary]")
    w(" ------ ---------- || -------------- ----------------- ---------- -----------")
    for k, b in enumerate(rows):
        km = b[2]
        w(
            f"{k + 1:5d}{b[0]:13.3f} ||{km / KM_PER_MOL_AU:12.6f}{km / KM_PER_MOL_DEBYE2:16.3f}"
            f"{km:14.3f}{km * NWCHEM_ARBITRARY:12.3f}"
        )
    w(" ----------------------------------------------------------------------------")
    return "\n".join(out) + "\n"


# ---- Psi4 -----------------------------------------------------------------------------------


def psi4(a):
    mol = a["mol"]
    out = []
    w = out.append
    w("")
    w("    -----------------------------------------------------------------------")
    w("          Psi4: An Open-Source Ab Initio Electronic Structure Package")
    w("                               Psi4 1.7 release")
    w("    -----------------------------------------------------------------------")
    w("")
    w("  ==> Geometry <==")
    w("")
    w("    Molecular point group: c1")
    w("    Full point group: C1")
    w("")
    w("    Geometry (in Bohr), charge = 0, multiplicity = 1:")
    w("")
    w("       Center              X                  Y                   Z               Mass       ")
    w("    ------------   -----------------  -----------------  -----------------  -----------------")
    for s, p, m in zip(symbols(mol), mol.atom_coords(), a["mass"]):
        w(f"{s:>10s}{p[0]:26.12f}{p[1]:19.12f}{p[2]:19.12f}{m:19.12f}")
    w("")
    w("  ==> Harmonic Vibrational Analysis <==")
    w("")
    natm = mol.natm
    first = 7 if natm > 2 else 6
    modes = list(zip(a["freq"], a["disp"], a["intensity"], a["reduced_mass"], a["force_mdyne"]))
    for start in range(0, len(modes), 3):
        block = modes[start : start + 3]

        def line(label, values):
            return f"  {label:<23s}" + "".join(f"{v:^20s}" for v in values)

        w(line("Vibration", [str(first + start + k) for k in range(len(block))]))
        w(line("Freq [cm^-1]", [f"{abs(b[0]):.4f}" + ("i" if b[0] < 0 else "") for b in block]))
        w(line("Irrep", ["A" for _ in block]))
        w(line("Reduced mass [u]", [f"{b[3]:.4f}" for b in block]))
        w(line("Force const [mDyne/A]", [f"{b[4]:.4f}" for b in block]))
        w(line("IR activ [km/mol]", [f"{b[2]:.4f}" for b in block]))
        w("  " + "-" * (22 + 20 * len(block)))
        for k, s in enumerate(symbols(mol)):
            d = [unit(b[1])[k] for b in block]
            w(f"{k + 1:7d}   {s:<15s}" + "".join(f"{x[0]:6.2f}{x[1]:6.2f}{x[2]:6.2f}  " for x in d) + " ")
        w("")
    w("  ==> Thermochemistry Components <==")
    return "\n".join(out) + "\n"


# ---- Q-Chem ---------------------------------------------------------------------------------


def qchem(a):
    mol = a["mol"]
    out = []
    w = out.append
    w("                  Welcome to Q-Chem")
    w("     A Quantum Leap Into The Future Of Chemistry")
    w("")
    w(" ----------------------------------------------------------------")
    w("             Standard Nuclear Orientation (Angstroms)")
    w("    I     Atom           X                Y                Z")
    w(" ----------------------------------------------------------------")
    for k, (s, p) in enumerate(zip(symbols(mol), mol.atom_coords() / ANGSTROM)):
        w(f"{k + 1:5d}      {s:<3s}{p[0]:17.10f}{p[1]:17.10f}{p[2]:17.10f}")
    w(" ----------------------------------------------------------------")
    w("")
    w(" **********************************************************************")
    w(" **                                                                  **")
    w(" **                       VIBRATIONAL ANALYSIS                       **")
    w(" **                       --------------------                       **")
    w(" **                                                                  **")
    w(" **        VIBRATIONAL FREQUENCIES (CM**-1) AND NORMAL MODES         **")
    w(" **     FORCE CONSTANTS (mDYN/ANGSTROM) AND REDUCED MASSES (AMU)     **")
    w(" **                  INFRARED INTENSITIES (KM/MOL)                   **")
    w(" **                                                                  **")
    w(" **********************************************************************")
    w("")
    w("")
    modes = list(zip(a["freq"], a["disp"], a["intensity"], a["reduced_mass"], a["force_mdyne"], a["dmu_dq"]))
    for start in range(0, len(modes), 3):
        block = modes[start : start + 3]

        def fields(first, rest, values):
            return "".join(f"{v:>{first if k == 0 else rest}}" for k, v in enumerate(values))

        active = ["YES" if b[2] > 1e-3 else "NO " for b in block]
        w(" Mode:" + fields(18, 23, [str(start + k + 1) for k in range(len(block))]))
        w(" Frequency:" + fields(13, 23, [f"{b[0]:.2f}" for b in block]))
        w(" Force Cnst:" + fields(12, 23, [f"{b[4]:.4f}" for b in block]))
        w(" Red. Mass:" + fields(13, 23, [f"{b[3]:.4f}" for b in block]))
        w(" IR Active:" + fields(13, 23, active))
        w(" IR Intens:" + fields(13, 23, [f"{b[2]:.3f}" for b in block]))
        w(" Raman Active:" + fields(10, 23, ["NO " if x == "YES" else "YES" for x in active]))
        w(" " * 15 + (" " * 8).join("X      Y      Z" for _ in block))
        for k, s in enumerate(symbols(mol)):
            d = [unit(b[1])[k] for b in block]
            w(f" {s:<9s}" + "  ".join(f"{x[0]:7.3f}{x[1]:7.3f}{x[2]:7.3f}" for x in d))
        w(" TransDip " + "  ".join(f"{x[0]:7.3f}{x[1]:7.3f}{x[2]:7.3f}" for x in (b[5] for b in block)))
        w("")
    w(" STANDARD THERMODYNAMIC QUANTITIES AT   298.15 K  AND     1.00 ATM")
    return "\n".join(out) + "\n"


WRITERS = {"gamess": gamess, "nwchem": nwchem, "psi4": psi4, "qchem": qchem}


def main():
    out_dir = sys.argv[1] if len(sys.argv) > 1 else "tests/fixtures/logs"
    for name, (atom, programs) in MOLECULES.items():
        a = analysis(atom)
        for program in programs:
            with open(os.path.join(out_dir, f"{name}_{program}_freq.out"), "w") as f:
                f.write(WRITERS[program](a))
        expected = {
            "frequency_cm1": [float(f) for f in a["freq"]],
            "ir_intensity_km_mol": [float(i) for i in a["intensity"]],
            "displacement_unit": [[[float(v) for v in p] for p in unit(d)] for d in a["disp"]],
            "geometry_bohr": [[float(v) for v in p] for p in a["mol"].atom_coords()],
        }
        with open(os.path.join(out_dir, f"{name}_freq.expected.json"), "w") as f:
            json.dump(expected, f, indent=1)
            f.write("\n")
        print(name, np.round(a["freq"], 2), np.round(a["intensity"], 3))


if __name__ == "__main__":
    main()
