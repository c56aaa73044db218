"""Normal-mode fixtures for tests/vibrations.rs, made with PySCF.

For each system, an RHF frequency calculation (analytic Hessian, PySCF's harmonic analysis,
IR intensities from dipole derivatives along each mode by central differences), written as

  tests/fixtures/modes/NAME.molden         PySCF's Molden writer, then [FREQ], [FR-COORD],
                                           [FR-NORM-COORD] and [INT] as Molden, ORCA and Gaussian
                                           write them
  tests/fixtures/modes/NAME.fchk           make_wavefunction_fixtures.py's fchk writer, then the
                                           Number of Normal Modes, Vib-NDim, Vib-E2, Vib-Modes and
                                           Vib-AtMass records as Gaussian 16 writes them (Vib-NDim
                                           holds the atom count, not the mode count)
  tests/fixtures/modes/NAME.expected.json  the frequencies (cm⁻¹, imaginary negative), IR
                                           intensities (km/mol), displacements and geometry (bohr)

Systems: water near its RHF/6-31G minimum (three real modes) and planar ammonia, the transition
state of its inversion (one imaginary mode). Run from the repository root:
    python3 scripts/make_mode_fixtures.py        (pyscf, numpy; see requirements.txt)
"""

import json
import os
import sys

import numpy as np
import pyscf
from pyscf import gto, lib, scf
from pyscf.hessian import thermo
from pyscf.tools import molden

sys.path.insert(0, os.path.dirname(__file__))
from make_wavefunction_fixtures import Fchk, write_fchk  # noqa: E402

OUT = os.path.join("tests", "fixtures", "modes")
# 1 (e²/amu) of squared dipole derivative per mass-weighted coordinate, in km/mol.
KM_PER_MOL = 974.8801
DELTA = 0.005  # bohr·amu^½, the central-difference step along a mode

# Water near its RHF/6-31G minimum; ammonia flattened to D3h (N–H 1.00 Å): a first-order saddle.
SYSTEMS = [
    ("water_rhf_631g", "O 0 0 0.1226; H 0 0.7633 -0.4905; H 0 -0.7633 -0.4905", "6-31g"),
    ("nh3_planar_rhf_sto3g", "N 0 0 0; H 1.0 0 0; H -0.5 0.8660254 0; H -0.5 -0.8660254 0", "sto-3g"),
]


def dipole(mol, coords):
    m = mol.set_geom_(coords, unit="Bohr", inplace=False)
    mf = scf.RHF(m).run(conv_tol=1e-11, verbose=0)
    return mf.dip_moment(unit="AU", verbose=0)


def frequencies(mol, mf):
    hess = mf.Hessian().kernel()
    result = thermo.harmonic_analysis(mol, hess, imaginary_freq=False)
    freq = np.asarray(result["freq_wavenumber"], dtype=float)
    modes = np.asarray(result["norm_mode"], dtype=float)  # Cartesian displacement per unit Q
    x0 = mol.atom_coords(unit="Bohr")
    intensities = []
    for d in modes:
        dmu = (dipole(mol, x0 + DELTA * d) - dipole(mol, x0 - DELTA * d)) / (2 * DELTA)
        intensities.append(KM_PER_MOL * float(dmu @ dmu))
    reduced = np.asarray(result["reduced_mass"], dtype=float)
    force = np.asarray(result["force_const_dyne"], dtype=float)
    return freq, modes, np.array(intensities), reduced, force


def append_molden(path, mol, freq, modes, intensities):
    xyz = mol.atom_coords(unit="Bohr")
    lines = ["[FREQ]"] + ["%12.4f" % f for f in freq]
    lines += ["[FR-COORD]"] + ["%-3s%14.6f%14.6f%14.6f" % (mol.atom_pure_symbol(i), *xyz[i]) for i in range(mol.natm)]
    lines += ["[FR-NORM-COORD]"]
    for k, d in enumerate(modes):
        lines.append("vibration %6d" % (k + 1))
        lines += ["%12.6f%12.6f%12.6f" % tuple(v) for v in d]
    lines += ["[INT]"] + ["%12.4f" % i for i in intensities]
    with open(path, "a") as f:
        f.write("\n".join(lines) + "\n")


def append_fchk(path, mol, freq, modes, intensities, reduced, force):
    n = len(freq)
    f = Fchk()
    f.int("Number of Normal Modes", n)
    f.int("Vib-NDim", mol.natm)
    # Frequencies, reduced masses, force constants, IR intensities, then ten more rows Gaussian
    # writes (Raman activities, depolarisations, …): zero here.
    f.reals("Vib-E2", np.concatenate([freq, reduced, force, intensities, np.zeros(10 * n)]))
    f.reals("Vib-Modes", modes.reshape(n, -1))
    f.reals("Vib-AtMass", mol.atom_mass_list(isotope_avg=True))
    with open(path, "a") as out:
        out.write("\n".join(f.lines) + "\n")


def main():
    os.makedirs(OUT, exist_ok=True)
    lib.num_threads(1)
    for name, geometry, basis in SYSTEMS:
        mol = gto.M(atom=geometry, basis=basis, symmetry=False, verbose=0)
        mf = scf.RHF(mol).run(conv_tol=1e-11)
        freq, modes, intensities, reduced, force = frequencies(mol, mf)
        stem = os.path.join(OUT, name)
        molden.from_scf(mf, stem + ".molden")
        append_molden(stem + ".molden", mol, freq, modes, intensities)
        title = "%s RHF/%s frequencies (PySCF %s)" % (name, basis, pyscf.__version__)
        write_fchk(stem + ".fchk", title, "RHF", basis.upper(), mol, mf, mol.nao_nr())
        append_fchk(stem + ".fchk", mol, freq, modes, intensities, reduced, force)
        expected = {
            "frequency_cm1": [float(f) for f in freq],
            "ir_intensity": [float(i) for i in intensities],
            "displacement": [d.tolist() for d in modes],
            "geometry_bohr": mol.atom_coords(unit="Bohr").tolist(),
        }
        with open(stem + ".expected.json", "w") as f:
            json.dump(expected, f, indent=1)
            f.write("\n")
        print("%-22s %s cm-1, %s km/mol" % (name, np.round(freq, 1), np.round(intensities, 1)))


if __name__ == "__main__":
    main()
