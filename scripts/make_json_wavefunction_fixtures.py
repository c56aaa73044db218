#!/usr/bin/env python3
"""Writes tests/fixtures/json/: PySCF wavefunctions as ORCA's `orca_2json` files and as QCSchema
results the way Psi4 writes them, beside the same wavefunction as a Molden file (PySCF's own
writer). tests/json_wavefunctions.rs checks that every JSON file opens with the Molden file's
orbitals, density, energies, occupations and spins.

Systems (symmetry off, so the input coordinates are kept):
  h2o_rhf      H2O  RHF/cc-pVDZ with one f (exponent 1.4) and one g (1.2) function added on O,
               pure functions (s to g: ORCA's f±3, g±3 and g±4 signs matter)
  h2o_cation   H2O+ UHF/cc-pVDZ doublet, pure functions
  h2o_cart     H2O  RHF/6-31G*, cartesian d (QCSchema only: ORCA has no cartesian functions)

Files:
  NAME.molden        pyscf.tools.molden.from_scf
  NAME.orca.json     ORCA 5's orca_2json layout, as the real files in eljost/pysisyphus
                     (commit a4ce10dd6d7fdcb3d813f1c730eb365d29041999: pysisyphus/wf_library/
                     orca_h2o_def2svp.json, orca_ch4_tzvpp.json, orca_ch4_sto3g_uhf.json,
                     tests/test_wavefunction/pyrrole/01_pyrrole_uhf.json) have it, with the
                     "ORCA Header" and the 4-space indentation of ORCA's writer; h2o_cation uses
                     ORCA 6.1's variant, as in faccts/opi (commit 95fb5980bc34f1323422075ac59f57aa
                     169057ff, tests/fixtures/json_files/opt.json): "Basis" instead of
                     "BasisFunctions", coordinates in Å ("CoordinateUnits": "Angs"),
                     OrbitalSymLabel/OrbitalSymmetry, 2-space indentation.
                     Layout: {"Molecule": {"Atoms": [{"BasisFunctions"|"Basis": [{"Coefficients",
                     "Exponents", "Shell": "s"|"p"|…}], "Coords", "ElementLabel", "ElementNumber",
                     "Idx", "NuclearCharge"}], "BaseName", "Charge", "CoordinateUnits", "HFTyp":
                     "RHF"|"UHF", "MolecularOrbitals": {"EnergyUnit": "Eh", "MOs":
                     [{"MOCoefficients", "Occupancy", "OrbitalEnergy"}], "OrbitalLabels":
                     ["0O   1s", …]}, "Multiplicity", "S-Matrix"}, "ORCA Header": {"Version"}}.
                     Conventions measured on those files against the S-Matrix they carry (max
                     |S - S(PySCF)| 8e-12, CᵀSC = 1 to 1e-12): pure p as z, x, y; d, f in the
                     order m = 0, +1, −1, +2, −2, …; f±3 (and g±3, ±4) with the opposite sign;
                     contraction coefficients of normalised primitives, normalised; UHF files
                     list the alpha then the beta orbitals (2·nao entries) and repeat the labels.
  NAME.qcschema.json Psi4's QCSchema AtomicResult, as QCArchive's Psi4 1.10 results in
                     MolSSI/QCFractal (commit ccb126b1743fe3b475dd663fb49e1b639343ce0c,
                     qcarchivetesting/qcarchivetesting/qcschema_v1_data/
                     sp_psi4_peroxide_energy_wfn.json.xz, its "result") have it: molecule
                     (symbols, flat geometry in bohr), properties (calcinfo_*), wavefunction
                     {basis: {name, center_data: {"CC-PVDZ_O1": {electron_shells:
                     [{angular_momentum: [l], harmonic_type, exponents, coefficients: [[…]]}]}},
                     atom_map}, restricted, scf_orbitals_a (nao × nmo, row after row),
                     scf_density_a, scf_fock_a, scf_eigenvalues_a, scf_occupations_a (per spin),
                     orbitals_a: "scf_orbitals_a", …}, written on one line as QCElemental's
                     .json() does. Psi4's conventions (psi4/psi4 psi4/driver/schema_wrapper.py,
                     _convert_basis and _convert_wavefunction; checked on the real file, whose
                     orbitals are orthonormal only with p as x, z, y): coefficients are
                     GaussianShell.coef, the contraction normalised with each primitive's x^l
                     normalisation folded in; pure functions in the order m = +l … −l (Psi4 maps
                     its 0, +1, −1, … order with a map meant for −l … +l, which reverses it);
                     cartesian components in the order xx, xy, xz, yy, yz, zz, all normalised
                     like x^l (the CCA standard). The QCSchema specification itself (MolSSI/
                     QCSchema docs/source/gen_schema_docs.py) asks for m = −l … +l; the reader
                     tells the two apart by the orbitals' orthonormality.

Run:   python scripts/make_json_wavefunction_fixtures.py   (PySCF 2.x)
"""
import json
import math
import os

import numpy as np
import pyscf
from pyscf import gto, scf
from pyscf.tools import molden

OUT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "tests", "fixtures", "json")
# Å per bohr for the Å coordinates of the ORCA 6.1 layout: CODATA 2018, the value orbcloud reads
# them with, so that they come back to the bohr PySCF computed in.
ANGSTROM = 0.529177210903

H2O = "O 0.0 0.0 0.1173; H 0.0 0.7572 -0.4692; H 0.0 -0.7572 -0.4692"

# name, basis, charge, 2S, method, cartesian, writes ORCA (None: no), ORCA 6.1 variant
SYSTEMS = [
    ("h2o_rhf", "cc-pvdz+fg", 0, 0, "RHF", False, "5"),
    ("h2o_cation", "cc-pvdz", 1, 1, "UHF", False, "6.1"),
    ("h2o_cart", "6-31g*", 0, 0, "RHF", True, None),
]
LETTERS = "spdfgh"


def dfact(n):
    return 1.0 if n <= 0 else n * dfact(n - 2)


def run(basis, charge, spin, method, cart):
    if basis == "cc-pvdz+fg":
        basis = {"O": gto.basis.load("cc-pvdz", "O") + [[3, [1.4, 1.0]], [4, [1.2, 1.0]]], "H": "cc-pvdz"}
    mol = gto.M(atom=H2O, basis=basis, charge=charge, spin=spin, cart=cart, symmetry=False, unit="Angstrom")
    mf = scf.RHF(mol) if method == "RHF" else scf.UHF(mol)
    mf.conv_tol = 1e-11
    mf.kernel()
    assert mf.converged
    return mol, mf


def spins(mf):
    """(coefficients nao × nmo, energies, occupations per spin) per spin."""
    if mf.mo_coeff.ndim == 2:
        return [(mf.mo_coeff, mf.mo_energy, mf.mo_occ)]
    return [(mf.mo_coeff[s], mf.mo_energy[s], mf.mo_occ[s]) for s in range(2)]


def shells(mol):
    """Per shell (atom, l, exponents, coefficients of normalised primitives, normalised, one shell per
    contraction) in PySCF's AO order."""
    out = []
    for b in range(mol.nbas):
        l = mol.bas_angular(b)
        exps = mol.bas_exp(b)
        # bas_ctr_coeff: the coefficients of normalised primitives.
        c = mol.bas_ctr_coeff(b)
        for k in range(c.shape[1]):
            coef = c[:, k]
            # Normalise the contraction of normalised primitives.
            s = sum(ci * cj * (2 * math.sqrt(ai * aj) / (ai + aj)) ** (l + 1.5) for ai, ci in zip(exps, coef) for aj, cj in zip(exps, coef))
            out.append((mol.bas_atom(b), l, exps.tolist(), (coef / math.sqrt(s)).tolist()))
    return out


def orca_rows(mol):
    """For each row of ORCA's order, (PySCF AO index, sign)."""
    rows = []
    offset = 0
    for atom, l, _, _ in shells(mol):
        if l == 1:
            order = [(2, 1), (0, 1), (1, 1)]  # z, x, y of PySCF's x, y, z
        else:
            ms = [0] + [x for k in range(1, l + 1) for x in (k, -k)]
            order = [(m + l, -1 if abs(m) in (3, 4) else 1) for m in ms]
        rows += [(offset + i, s) for i, s in order]
        offset += 2 * l + 1
    assert offset == mol.nao
    return rows


def orca_labels(mol):
    """ORCA's function labels: atom index and symbol, the shell's number within its l, the
    function ("0O   1s", "0O   1pz", "0O   1dx2y2", "0O   1f-3")."""
    names = {0: ["s"], 1: ["pz", "px", "py"], 2: ["dz2", "dxz", "dyz", "dx2y2", "dxy"],
             3: ["f0", "f+1", "f-1", "f+2", "f-2", "f+3", "f-3"],
             4: ["g0", "g+1", "g-1", "g+2", "g-2", "g+3", "g-3", "g+4", "g-4"]}
    labels = []
    count = {}
    for atom, l, _, _ in shells(mol):
        count[(atom, l)] = count.get((atom, l), 0) + 1
        symbol = mol.atom_pure_symbol(atom)
        labels += [f"{atom}{symbol}   {count[(atom, l)]}{f}" for f in names[l]]
    return labels


def write_orca(name, mol, mf, version):
    orca6 = version == "6.1"
    rows = orca_rows(mol)
    scale = ANGSTROM if orca6 else 1.0
    atoms = []
    basis = shells(mol)
    for a in range(mol.natm):
        shell_list = [
            {"Coefficients": c, "Exponents": e, "Shell": LETTERS[l]} for (atom, l, e, c) in basis if atom == a
        ]
        entry = {
            ("Basis" if orca6 else "BasisFunctions"): shell_list,
            "Coords": (mol.atom_coord(a) * scale).tolist(),
            "ElementLabel": mol.atom_pure_symbol(a),
            "ElementNumber": int(mol.atom_charge(a)),
            "Idx": a,
            "NuclearCharge": float(mol.atom_charge(a)),
        }
        atoms.append(entry)
    mos = []
    for c, e, occ in spins(mf):
        for k in range(c.shape[1]):
            mo = {
                "MOCoefficients": [s * c[i, k] for i, s in rows],
                "Occupancy": float(occ[k]),
                "OrbitalEnergy": float(e[k]),
            }
            if orca6:
                mo["OrbitalSymLabel"] = "A"
                mo["OrbitalSymmetry"] = 0
            mos.append(mo)
    labels = orca_labels(mol) * len(spins(mf))
    s = mol.intor("int1e_ovlp")
    index = [i for i, _ in rows]
    sign = np.array([sg for _, sg in rows])
    s_orca = s[np.ix_(index, index)] * np.outer(sign, sign)
    molecule = {
        "Atoms": atoms,
        "BaseName": name,
        "Charge": mol.charge,
        "CoordinateUnits": "Angs" if orca6 else "Bohrs",
        "HFTyp": "UHF" if len(spins(mf)) == 2 else "RHF",
        "MolecularOrbitals": {"EnergyUnit": "Eh", "MOs": mos, "OrbitalLabels": labels},
        "Multiplicity": mol.spin + 1,
        "S-Matrix": s_orca.tolist(),
    }
    if orca6:
        molecule["PointGroup"] = "C1"
        molecule["Origin"] = [0.0, 0.0, 0.0]
        doc = {"ORCA Header": {"Version": "6.1.x"}, "Molecule": molecule}
        text = json.dumps(doc, indent=2)
    else:
        doc = {"Molecule": molecule, "ORCA Header": {"Version": "5.0 - current"}}
        text = json.dumps(doc, indent=4, sort_keys=True)
    # The orbitals in ORCA's order are orthonormal in ORCA's overlap (what the real files show).
    for c, _, _ in spins(mf):
        co = np.array([sg * c[i, :] for i, sg in rows])
        assert abs(co.T @ s_orca @ co - np.eye(co.shape[1])).max() < 1e-8
    with open(os.path.join(OUT, f"{name}.orca.json"), "w") as f:
        f.write(text + "\n")


def psi4_rows(mol):
    """For each function of Psi4's QCSchema order, (PySCF AO index, factor on the coefficient)."""
    rows = []
    offset = 0
    pure = not mol.cart
    norms = np.sqrt(np.diag(mol.intor("int1e_ovlp")))
    for atom, l, _, _ in shells(mol):
        if pure and l == 1:
            rows += [(offset + 0, 1.0), (offset + 2, 1.0), (offset + 1, 1.0)]  # x, z, y: m = +1, 0, −1
            offset += 3
        elif pure:
            rows += [(offset + m + l, 1.0) for m in range(l, -l - 1, -1)]  # m = +l … −l
            offset += 2 * l + 1
        else:
            # PySCF's cartesian order is the same (xx, xy, xz, yy, yz, zz); its components are
            # scaled so that the pure combinations are normalised. Psi4's are normalised like
            # x^l: ψ = Σ C χ = Σ C·|χ|/|f| f, |f|² = (2a−1)!!(2b−1)!!(2c−1)!!/(2l−1)!!.
            k = 0
            for a in range(l, -1, -1):
                for b in range(l - a, -1, -1):
                    c = l - a - b
                    f = math.sqrt(dfact(2 * a - 1) * dfact(2 * b - 1) * dfact(2 * c - 1) / dfact(2 * l - 1))
                    rows.append((offset + k, norms[offset + k] / f))
                    k += 1
            offset += k
    assert offset == mol.nao, (offset, mol.nao)
    return rows


def write_qcschema(name, basis_name, mol, mf, protocol):
    rows = psi4_rows(mol)
    htype = "cartesian" if mol.cart else "spherical"
    centers = {}
    atom_map = []
    basis = shells(mol)
    counter = {}
    by_content = {}
    for a in range(mol.natm):
        symbol = mol.atom_pure_symbol(a)
        electron_shells = []
        for atom, l, e, c in basis:
            if atom != a:
                continue
            # GaussianShell.coef: the x^l primitive normalisation folded in.
            n = [math.sqrt((2 * x / math.pi) ** 1.5 * (4 * x) ** l / dfact(2 * l - 1)) for x in e]
            electron_shells.append(
                {"angular_momentum": [l], "harmonic_type": htype, "exponents": e,
                 "coefficients": [[ci * ni for ci, ni in zip(c, n)]]}
            )
        key = json.dumps(electron_shells, sort_keys=True)
        if key not in by_content:
            counter[symbol] = counter.get(symbol, 0) + 1
            by_content[key] = f"{basis_name.upper().replace('+', '_')}_{symbol}{counter[symbol]}"
            centers[by_content[key]] = {"electron_shells": electron_shells}
        atom_map.append(by_content[key])
    sp = spins(mf)
    restricted = len(sp) == 1
    wfn = {"basis": {"name": basis_name.upper(), "center_data": centers, "atom_map": atom_map},
           "restricted": restricted}
    index = [i for i, _ in rows]
    factor = np.array([f for _, f in rows])
    # QCElemental keeps only the alpha fields of a restricted result.
    roles = ["orbitals", "density", "eigenvalues", "occupations"] if protocol == "all" else ["orbitals", "eigenvalues"]
    for (c, e, occ), suffix in zip(sp, "ab"):
        c_file = c[index, :] * factor[:, None]
        per_spin = occ / 2 if restricted else occ
        fields = {
            "orbitals": c_file.ravel().tolist(),
            "density": ((c_file * per_spin) @ c_file.T).ravel().tolist(),
            "eigenvalues": e.tolist(),
            "occupations": per_spin.tolist(),
        }
        for role in roles:
            wfn[f"scf_{role}_{suffix}"] = fields[role]
    for suffix in "a" if restricted else "ab":
        for role in roles:
            wfn[f"{role}_{suffix}"] = f"scf_{role}_{suffix}"
    nalpha, nbeta = mol.nelec
    doc = {
        "id": None,
        "schema_name": "qcschema_output",
        "schema_version": 1,
        "molecule": {
            "schema_name": "qcschema_molecule", "schema_version": 2, "validated": True,
            "symbols": [mol.atom_pure_symbol(a) for a in range(mol.natm)],
            "geometry": mol.atom_coords().ravel().tolist(),
            "name": "H2O", "molecular_charge": float(mol.charge), "molecular_multiplicity": mol.spin + 1,
            "fix_com": True, "fix_orientation": True,
        },
        "driver": "energy",
        "model": {"method": "hf", "basis": basis_name},
        "keywords": {"reference": "uhf" if len(sp) == 2 else "rhf"},
        "protocols": {"wavefunction": protocol},
        "extras": {"qcvars": {"CURRENT ENERGY": float(mf.e_tot)}},
        "provenance": {"creator": "Psi4", "version": "1.10", "routine": "psi4.schema_runner.run_qcschema"},
        "properties": {
            "calcinfo_nbasis": mol.nao, "calcinfo_nmo": mol.nao, "calcinfo_nalpha": nalpha,
            "calcinfo_nbeta": nbeta, "calcinfo_natom": mol.natm, "return_energy": float(mf.e_tot),
            "scf_total_energy": float(mf.e_tot),
        },
        "wavefunction": wfn,
        "return_result": float(mf.e_tot),
        "stdout": None, "stderr": None, "native_files": {}, "success": True, "error": None,
    }
    with open(os.path.join(OUT, f"{name}.qcschema.json"), "w") as f:
        f.write(json.dumps(doc))


def main():
    os.makedirs(OUT, exist_ok=True)
    print("PySCF", pyscf.__version__)
    for name, basis, charge, spin, method, cart, orca in SYSTEMS:
        mol, mf = run(basis, charge, spin, method, cart)
        molden.from_scf(mf, os.path.join(OUT, f"{name}.molden"))
        if orca:
            write_orca(name, mol, mf, orca)
        # The restricted water as "orbitals_and_eigenvalues" (no occupations: they come from
        # calcinfo_nalpha/nbeta), the others as "all".
        write_qcschema(name, basis, mol, mf, "orbitals_and_eigenvalues" if name == "h2o_rhf" else "all")
        print(f"{name}: {mol.nao} functions, E = {mf.e_tot:.10f}")


if __name__ == "__main__":
    main()
