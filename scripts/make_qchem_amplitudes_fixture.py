#!/usr/bin/env python3
"""Writes tests/fixtures/excited/formaldehyde_qchem_tda.fchk, a formatted checkpoint in the
layout Q-Chem writes for a CIS or TDA job run with GUI = 2, from PySCF's TDA of formaldehyde
(RHF/6-31G, three triplets and three singlets), and formaldehyde_qchem_tda.expected.json: per
state PySCF's excitation energy, oscillator strength and natural transition orbitals
(`td.get_nto`: the weights, and each pair's hole and particle evaluated at points).

The layout is that of Q-Chem 5.4's and 7.0's real files in cclib's regression data
(github.com/cclib/cclib, commit 21daa960123d28aa21eeaaacc2a1dea39e136829,
data/FChk/basicQChem5.4/water_cis.fchk and dvb_td.fchk; data/FChk/basicQChem7.0/water_cis.fchk),
read record by record:

  - line 1 `Jobname.Temp`, line 2 `SP        R` then the basis name (10 + 30 + 20 columns);
  - the records in Q-Chem's order: counts, `Atomic numbers`, `Current cartesian coordinates`,
    `Nuclear charges`, the shell counts, `Shell types` (a Pople basis's valence shells as SP,
    type -1, their p coefficients in `P(S=P) Contraction coefficients`, zero for the others),
    `Coordinates of each shell`, `Overlap Matrix` and `Core Hamiltonian Matrix` (lower
    triangles), then `Number of Excited States`, `Excitation Energies` (hartree), `Oscillator
    Strengths`, `Alpha Amplitudes` and `Beta Amplitudes`, then `Number of independent
    functions`, `Alpha MO coefficients`, `Alpha Orbital Energies`, `Total SCF Density`,
    `Pure Switching` and the multipole records;
  - the states: the triplets first, then the singlets, each in order of energy (water_cis:
    its log's states 1, 3, 4, 5, 8 are the file's 1-5); the triplets' oscillator strengths 0;
  - the amplitudes: per state occupied-major (X_ia at (state * o + i) * v + a), square-summing to
    1/2 per state (the log prints sqrt(2) X); the beta record repeats the alpha one, triplets
    included.

PySCF's restricted TDA normalises X to 1/2 as Q-Chem does; the molecular orbitals are written as
the fchk writes them (each basis function normalised, Gaussian's function order), with
scripts/make_wavefunction_fixtures.py's helpers. td.get_nto renormalises X in place, so the
amplitudes are taken before it runs.

Run:   OMP_NUM_THREADS=1 python3 scripts/make_qchem_amplitudes_fixture.py   (PySCF, numpy)
"""
import json
import sys
from pathlib import Path

import numpy as np
from pyscf import gto, scf, tdscf
from pyscf.data import nist

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))
import make_wavefunction_fixtures as fx  # noqa: E402

OUT = HERE.parent / "tests" / "fixtures" / "excited"
STEM = "formaldehyde_qchem_tda"
GEOMETRY = "C 0 0 -0.529; O 0 0 0.676; H 0 0.935 -1.114; H 0 -0.935 -1.114"
BASIS = "6-31G"
N_STATES = 3
N_POINTS = 40
SEED = 11


def sp_shells(mol):
    """The fchk's shells with each atom's s and p shells of equal exponents joined into one SP
    shell (as Q-Chem writes a Pople basis), and per fchk function its PySCF AO index."""
    shells, order = fx.shells_and_order(mol)
    # Each shell's functions in the fchk's order, as PySCF AO indices.
    spans, k = [], 0
    for t, _, _, _ in shells:
        n = 1 if t == 0 else 3 if t == 1 else None
        assert n is not None, "6-31G has s and p shells only"
        spans.append(list(order[k : k + n]))
        k += n
    out, out_order, used = [], [], set()
    for a, (t, atom, e, c) in enumerate(shells):
        if a in used:
            continue
        if t == 0:
            twin = next(
                (b for b, (u, at, f, _) in enumerate(shells)
                 if u == 1 and at == atom and b not in used and len(f) == len(e) and np.allclose(f, e)),
                None,
            )
            if twin is not None:
                used.add(twin)
                out.append((-1, atom, e, c, shells[twin][3]))
                out_order += spans[a] + spans[twin]
                continue
        out.append((t, atom, e, c, np.zeros_like(c)))
        out_order += spans[a]
    assert sorted(out_order) == list(range(mol.nao_nr()))
    return out, np.array(out_order)


def lower(m):
    return np.concatenate([m[i, : i + 1] for i in range(m.shape[0])])


def main():
    OUT.mkdir(parents=True, exist_ok=True)
    mol = gto.M(atom=GEOMETRY, basis=BASIS, unit="Angstrom", verbose=0)
    mf = scf.RHF(mol).run(conv_tol=1e-12)
    nocc = mol.nelectron // 2
    nvir = mol.nao_nr() - nocc
    runs = []
    for singlet in (False, True):  # Q-Chem's order: triplets, then singlets
        td = tdscf.TDA(mf)
        td.singlet = singlet
        td.nstates = N_STATES
        td.conv_tol = 1e-12
        td.kernel()
        assert all(td.converged)
        x = [np.array(xy[0], copy=True) for xy in td.xy]
        for xi in x:
            assert abs((xi**2).sum() - 0.5) < 1e-10
        f = td.oscillator_strength(gauge="length") if singlet else np.zeros(N_STATES)
        runs.append((singlet, td, x, f))

    shells, order = sp_shells(mol)
    norm = np.sqrt(mol.intor("int1e_ovlp").diagonal())
    to_fchk = lambda m: (norm[:, None] * m * norm[None, :])[np.ix_(order, order)]  # noqa: E731
    c = fx.to_gaussian(mol, order, mf.mo_coeff)
    p = np.linalg.multi_dot([c[:, :nocc], c[:, :nocc].T]) * 2.0

    f = fx.Fchk()
    f.lines.append("Jobname.Temp")
    f.lines.append("%-10s%-30s%-20s" % ("SP", "R", BASIS))
    f.int("Number of atoms", mol.natm)
    f.int("Charge", mol.charge)
    f.int("Multiplicity", mol.spin + 1)
    f.int("Number of electrons", mol.nelectron)
    f.int("Number of alpha electrons", nocc)
    f.int("Number of beta electrons", nocc)
    z = [int(gto.charge(mol.atom_symbol(i))) for i in range(mol.natm)]
    f.ints("Atomic numbers", z)
    xyz = mol.atom_coords(unit="Bohr")
    f.reals("Current cartesian coordinates", xyz)
    f.reals("Nuclear charges", z)
    f.int("Number of basis functions", mol.nao_nr())
    f.int("Number of contracted shells", len(shells))
    f.int("Number of primitive shells", sum(len(s[2]) for s in shells))
    f.int("Highest angular momentum", max(abs(s[0]) for s in shells))
    f.int("Largest degree of contraction", max(len(s[2]) for s in shells))
    f.ints("Shell types", [s[0] for s in shells])
    f.ints("Number of primitives per shell", [len(s[2]) for s in shells])
    f.ints("Shell to atom map", [s[1] + 1 for s in shells])
    f.reals("Primitive exponents", np.concatenate([s[2] for s in shells]))
    f.reals("Contraction coefficients", np.concatenate([s[3] for s in shells]))
    f.reals("P(S=P) Contraction coefficients", np.concatenate([s[4] for s in shells]))
    f.reals("Coordinates of each shell", np.concatenate([xyz[s[1]] for s in shells]))
    f.reals("Overlap Matrix", lower(to_fchk(mol.intor("int1e_ovlp"))))
    f.reals("Core Hamiltonian Matrix", lower(to_fchk(mf.get_hcore())))
    f.int("Number of Excited States", 2 * N_STATES)
    f.reals("Excitation Energies", np.concatenate([run[1].e for run in runs]))
    f.reals("Oscillator Strengths", np.concatenate([run[3] for run in runs]))
    amplitudes = np.concatenate([np.ravel(xi) for run in runs for xi in run[2]])
    f.reals("Alpha Amplitudes", amplitudes)
    f.reals("Beta Amplitudes", amplitudes)
    f.int("Number of independent functions", mol.nao_nr())
    f.reals("Alpha MO coefficients", c.T)
    f.reals("Alpha Orbital Energies", mf.mo_energy)
    f.reals("Total SCF Density", lower(p))
    f.int("Pure Switching", 1)
    f.reals("Dipole_Data", mf.dip_moment(unit="AU", verbose=0))
    (OUT / (STEM + ".fchk")).write_text("\n".join(f.lines) + "\n")

    # The reference: per state in order of energy, PySCF's NTOs at random points.
    rng = np.random.default_rng(SEED)
    lo, hi = xyz.min(0) - 3.0, xyz.max(0) + 3.0
    points = lo + (hi - lo) * rng.random((N_POINTS, 3))
    ao = mol.eval_gto("GTOval_sph", points)
    states = []
    for singlet, td, x, strengths in runs:
        for k in range(N_STATES):
            weights, nto = td.get_nto(state=k + 1, verbose=0)
            pairs = []
            for j, w in enumerate(weights[:5]):
                if w < 1e-4:
                    break
                pairs.append({
                    "weight": float(w),
                    "hole": (ao @ nto[:, j]).tolist(),
                    "particle": (ao @ nto[:, nocc + j]).tolist(),
                })
            states.append({
                "spin": "Singlet" if singlet else "Triplet",
                "energy_ev": float(td.e[k] * nist.HARTREE2EV),
                "oscillator_strength": float(strengths[k]),
                "ntos": pairs,
            })
    states.sort(key=lambda s: s["energy_ev"])
    ref = {"nocc": nocc, "nvir": nvir, "points_bohr": points.tolist(), "states": states}
    (OUT / (STEM + ".expected.json")).write_text(json.dumps(ref, indent=1) + "\n")
    for s in states:
        print("%-8s %8.4f eV  f %.5f  weights %s" % (s["spin"], s["energy_ev"], s["oscillator_strength"],
                                                      [round(p["weight"], 5) for p in s["ntos"]]))


if __name__ == "__main__":
    main()
