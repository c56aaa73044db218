#!/usr/bin/env python3
"""Writes tests/fixtures/wavefunctions/: small SCF wavefunctions from PySCF as Molden and
formatted-checkpoint (fchk) files, with reference values for tests/fixture_wavefunctions.rs.

For every system NAME below it writes
  NAME.molden         pyscf.tools.molden.from_scf (alpha and beta blocks for UHF)
  NAME.fchk           this script's fchk writer (Gaussian conventions, see write_fchk)
  NAME.expected.json  50 random points (fixed seed) in the molecule's bounding box padded by
                      4 bohr, PySCF's values there (mol.eval_gto @ mo_coeff): the alpha HOMO
                      and LUMO (by energy), the total density and, for UHF, the spin density;
                      the electron count and the HOMO/LUMO energies (hartree).

Systems (symmetry off, so the input coordinates are kept):
  h2o_cart_631gs        H2O   RHF/6-31G*   cartesian d (6D)
  h2o_ccpvtz            H2O   RHF/cc-pVTZ  pure d and f
  benzene_631gs         C6H6  B3LYP/6-31G* pure d; only the occupied and the lowest virtual
                        orbitals are written (the full set would exceed the size limit)
  h3o_cation_631gss     H3O+  RHF/6-31G**
  h2o_cation_uhf_631gs  H2O+  UHF/6-31G*   doublet

fchk conventions: coordinates in bohr; shell types 0 s, 1 p, +l cartesian, -l pure;
contraction coefficients for normalised primitives; pure functions in the order
m = 0, +1, -1, +2, -2, ... (PySCF: m = -l..+l), p as x, y, z; cartesian d as xx yy zz xy xz yz,
f as xxx yyy zzz xyy xxy xxz xzz yzz yyz xyz, g and higher reverse alphabetical; every
cartesian component has unit norm (PySCF normalises only x^l, so coefficients are scaled by
sqrt(S_ii)). Orbital signs are PySCF's.

Run:   python scripts/make_wavefunction_fixtures.py [--check]
       (PySCF 2.x; the output is deterministic on a given machine.) --check also reads each
       fchk back with IOData and evaluates it with GBasis (pip install qc-iodata qc-gbasis),
       comparing with PySCF.
"""
import json
import os
import sys

import numpy as np
import pyscf
from pyscf import dft, gto, lib, scf
from pyscf.tools import molden

OUT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "tests", "fixtures", "wavefunctions")
N_POINTS = 50
PAD = 4.0
SEED = 20240601
MAX_BYTES = 150_000

H2O = "O 0.0 0.0 0.1173; H 0.0 0.7572 -0.4692; H 0.0 -0.7572 -0.4692"
H3O = ("O 0.0 0.0 0.0810; H 0.0 0.9350 -0.2700; H 0.8097 -0.4675 -0.2700; "
       "H -0.8097 -0.4675 -0.2700")


def benzene():
    atoms = []
    for k in range(6):
        a = np.pi / 3 * k
        atoms.append("C %.6f %.6f 0.0" % (1.3915 * np.cos(a), 1.3915 * np.sin(a)))
        atoms.append("H %.6f %.6f 0.0" % (2.4715 * np.cos(a), 2.4715 * np.sin(a)))
    return "; ".join(atoms)


# name, geometry (angstrom), basis, basis label, cartesian, charge, 2S, method, MOs kept
SYSTEMS = [
    ("h2o_cart_631gs", H2O, "6-31G*", "6-31G(d)", True, 0, 0, "RHF", None),
    ("h2o_ccpvtz", H2O, "cc-pVTZ", "CC-pVTZ", False, 0, 0, "RHF", None),
    ("benzene_631gs", benzene(), "6-31G*", "6-31G(d)", False, 0, 0, "RB3LYP", 42),
    ("h3o_cation_631gss", H3O, "6-31G**", "6-31G(d,p)", False, 1, 0, "RHF", None),
    ("h2o_cation_uhf_631gs", H2O, "6-31G*", "6-31G(d)", False, 1, 1, "UHF", None),
]


def run_scf(geometry, basis, cart, charge, spin, method):
    mol = gto.M(atom=geometry, basis=basis, cart=cart, charge=charge, spin=spin, symmetry=False,
                unit="Angstrom", verbose=0)
    if method == "RHF":
        mf = scf.RHF(mol)
    elif method == "UHF":
        mf = scf.UHF(mol)
    elif method == "RB3LYP":
        mf = dft.RKS(mol)
        mf.xc = "b3lyp"
    else:
        raise ValueError(method)
    mf.conv_tol = 1e-11
    mf.kernel()
    assert mf.converged, method
    return mol, mf


# ----------------------------------------------------------------------------------------
# Function order: for each fchk basis function, its PySCF AO index.


def gaussian_cartesian_order(l):
    """PySCF component index of each Gaussian cartesian component."""
    pyscf = [(lx, ly, l - lx - ly) for lx in range(l, -1, -1) for ly in range(l - lx, -1, -1)]
    if l == 2:
        names = "xx yy zz xy xz yz".split()
    elif l == 3:
        names = "xxx yyy zzz xyy xxy xxz xzz yzz yyz xyz".split()
    else:
        return list(range(len(pyscf)))[::-1]
    return [pyscf.index((n.count("x"), n.count("y"), n.count("z"))) for n in names]


def gaussian_pure_order(l):
    """PySCF component index (m + l) of each Gaussian pure component m = 0, +1, -1, ..."""
    out = [l]
    for m in range(1, l + 1):
        out += [l + m, l - m]
    return out


def shells_and_order(mol):
    """fchk shells (type, atom, exponents, coefficients) and the PySCF AO of each fchk function."""
    shells, order = [], []
    off = 0
    for ib in range(mol.nbas):
        l = int(mol.bas_angular(ib))
        exps = mol.bas_exp(ib)
        cs = mol.bas_ctr_coeff(ib)
        n = (l + 1) * (l + 2) // 2 if mol.cart else 2 * l + 1
        if l <= 1:
            t, comp = l, list(range(n))
        elif mol.cart:
            t, comp = l, gaussian_cartesian_order(l)
        else:
            t, comp = -l, gaussian_pure_order(l)
        for c in range(cs.shape[1]):
            shells.append((t, int(mol.bas_atom(ib)), exps, cs[:, c]))
            order.extend(off + c * n + k for k in comp)
        off += cs.shape[1] * n
    assert off == mol.nao_nr() and sorted(order) == list(range(off))
    return shells, np.array(order)


def to_gaussian(mol, order, mo_coeff):
    """MO coefficients (AO x MO) in fchk function order, each AO unit-normalised."""
    norm = np.sqrt(mol.intor("int1e_ovlp").diagonal())
    return (norm[:, None] * mo_coeff)[order]


# ----------------------------------------------------------------------------------------
# fchk writer.


class Fchk:
    def __init__(self):
        self.lines = []

    def int(self, label, v):
        self.lines.append("%-43s%-6s%12d" % (label, "I", v))

    def real(self, label, v):
        self.lines.append("%-43s%-6s%22.15E" % (label, "R", v))

    def ints(self, label, v):
        v = [int(x) for x in v]
        self.lines.append("%-43s%-4sN=%12d" % (label, "I", len(v)))
        for i in range(0, len(v), 6):
            self.lines.append("".join("%12d" % x for x in v[i:i + 6]))

    def reals(self, label, v):
        v = [float(x) for x in np.ravel(v)]
        self.lines.append("%-43s%-4sN=%12d" % (label, "R", len(v)))
        for i in range(0, len(v), 5):
            self.lines.append("".join("%16.8E" % x for x in v[i:i + 5]))


def write_fchk(path, title, method, basis_label, mol, mf, keep):
    shells, order = shells_and_order(mol)
    nbf = len(order)
    f = Fchk()
    f.lines.append(title[:72])
    f.lines.append("%-10s%-30s%-30s" % ("SP", method, basis_label))
    neleca, nelecb = mol.nelec
    f.int("Number of atoms", mol.natm)
    f.int("Charge", mol.charge)
    f.int("Multiplicity", mol.spin + 1)
    f.int("Number of electrons", mol.nelectron)
    f.int("Number of alpha electrons", neleca)
    f.int("Number of beta electrons", nelecb)
    f.int("Number of basis functions", nbf)
    f.int("Number of independent functions", keep)
    f.ints("Atomic numbers", [gto.charge(mol.atom_symbol(i)) for i in range(mol.natm)])
    f.reals("Nuclear charges", [mol.atom_charge(i) for i in range(mol.natm)])
    f.reals("Current cartesian coordinates", mol.atom_coords(unit="Bohr"))
    f.ints("Shell types", [s[0] for s in shells])
    f.ints("Number of primitives per shell", [len(s[2]) for s in shells])
    f.ints("Shell to atom map", [s[1] + 1 for s in shells])
    f.reals("Primitive exponents", np.concatenate([s[2] for s in shells]))
    f.reals("Contraction coefficients", np.concatenate([s[3] for s in shells]))
    f.real("Total Energy", mf.e_tot)
    if mf.mo_coeff.ndim == 3:
        spins = [("Alpha", mf.mo_energy[0], mf.mo_coeff[0]), ("Beta", mf.mo_energy[1], mf.mo_coeff[1])]
    else:
        spins = [("Alpha", mf.mo_energy, mf.mo_coeff)]
    for name, energies, _ in spins:
        f.reals("%s Orbital Energies" % name, energies[:keep])
    for name, _, coeff in spins:
        c = to_gaussian(mol, order, coeff[:, :keep])
        f.reals("%s MO coefficients" % name, c.T)  # one orbital per row
    with open(path, "w") as out:
        out.write("\n".join(f.lines) + "\n")


# ----------------------------------------------------------------------------------------
# Reference values.


def random_points(mol):
    rng = np.random.default_rng(SEED)
    xyz = mol.atom_coords(unit="Bohr")
    lo, hi = xyz.min(0) - PAD, xyz.max(0) + PAD
    return lo + (hi - lo) * rng.random((N_POINTS, 3))


def spin_sets(mf):
    if mf.mo_coeff.ndim == 3:
        return [(mf.mo_energy[0], mf.mo_coeff[0], mf.mo_occ[0]), (mf.mo_energy[1], mf.mo_coeff[1], mf.mo_occ[1])]
    return [(mf.mo_energy, mf.mo_coeff, mf.mo_occ)]


def expected(name, mol, mf, keep, points):
    ao = mol.eval_gto("GTOval_cart" if mol.cart else "GTOval_sph", points)
    sets = spin_sets(mf)
    e_a, c_a, o_a = sets[0]
    occ = np.where(o_a > 0)[0]
    virt = np.where(o_a == 0)[0]
    homo = int(occ[np.argmax(e_a[occ])])
    lumo = int(virt[np.argmin(e_a[virt])])
    assert homo < keep and lumo < keep
    density = sum(((ao @ c[:, o > 0]) ** 2 * o[o > 0]).sum(1) for _, c, o in sets)
    out = {
        "name": name,
        "restricted": len(sets) == 1,
        "cartesian": bool(mol.cart),
        "charge": int(mol.charge),
        "multiplicity": int(mol.spin + 1),
        "n_electrons": int(mol.nelectron),
        "n_basis": int(mol.nao_nr()),
        "n_orbitals_per_spin": int(keep),
        "homo_index": homo,
        "lumo_index": lumo,
        "homo_energy": float(e_a[homo]),
        "lumo_energy": float(e_a[lumo]),
        "points": [[float(x) for x in p] for p in points],
        "homo": [float(x) for x in ao @ c_a[:, homo]],
        "lumo": [float(x) for x in ao @ c_a[:, lumo]],
        "density": [float(x) for x in density],
    }
    if len(sets) == 2:
        (_, ca, oa), (_, cb, ob) = sets
        spin = ((ao @ ca[:, oa > 0]) ** 2).sum(1) - ((ao @ cb[:, ob > 0]) ** 2).sum(1)
        out["spin_density"] = [float(x) for x in spin]
    return out


def check_with_iodata(path, ref):
    """Reads an fchk with IOData, evaluates it with GBasis and returns the worst differences."""
    from gbasis.evals.eval import evaluate_basis
    from gbasis.wrappers import from_iodata
    from iodata import load_one

    data = load_one(path)
    basis = from_iodata(data)
    pts = np.array(ref["points"])
    ao = evaluate_basis(basis, pts, screen_basis=False).T
    m = data.mo
    ca = m.coeffsa
    worst = {
        "homo": np.abs(ao @ ca[:, ref["homo_index"]] - ref["homo"]).max(),
        "lumo": np.abs(ao @ ca[:, ref["lumo_index"]] - ref["lumo"]).max(),
    }
    if m.kind == "unrestricted":
        sets = [(m.coeffsa, m.occsa), (m.coeffsb, m.occsb)]
    else:
        sets = [(m.coeffs, m.occs)]
    density = sum(((ao @ c[:, o > 0]) ** 2 * o[o > 0]).sum(1) for c, o in sets)
    worst["density_rel"] = (np.abs(density - ref["density"]) / np.maximum(np.abs(ref["density"]), 1e-2)).max()
    worst["electrons"] = sum(o.sum() for _, o in sets) - ref["n_electrons"]
    return worst


def main():
    check = "--check" in sys.argv[1:]
    os.makedirs(OUT, exist_ok=True)
    lib.num_threads(1)
    for name, geometry, basis, basis_label, cart, charge, spin, method, keep in SYSTEMS:
        mol, mf = run_scf(geometry, basis, cart, charge, spin, method)
        keep = keep or mol.nao_nr()
        stem = os.path.join(OUT, name)
        if keep == mol.nao_nr():
            molden.from_scf(mf, stem + ".molden")
        else:
            with open(stem + ".molden", "w") as f:
                molden.header(mol, f)
                molden.orbital_coeff(mol, f, mf.mo_coeff[:, :keep], ene=mf.mo_energy[:keep],
                                     occ=mf.mo_occ[:keep])
        title = "%s %s/%s (PySCF %s)" % (name, method, basis, pyscf.__version__)
        write_fchk(stem + ".fchk", title, method, basis_label, mol, mf, keep)
        ref = expected(name, mol, mf, keep, random_points(mol))
        with open(stem + ".expected.json", "w") as f:
            # One key per line; floats as repr (exact round trip).
            f.write("{\n" + ",\n".join(" %s: %s" % (json.dumps(k), json.dumps(v)) for k, v in ref.items()) + "\n}\n")
        sizes = {ext: os.path.getsize(stem + ext) for ext in (".molden", ".fchk", ".expected.json")}
        for ext, size in sizes.items():
            assert size < MAX_BYTES, (name + ext, size)
        print("%-22s nao=%3d nmo=%3d E=%.10f  %s" % (name, mol.nao_nr(), keep, mf.e_tot,
                                                    " ".join("%s %d B" % kv for kv in sizes.items())))
        if check:
            print("    IOData+GBasis vs PySCF:", {k: float("%.3g" % v) for k, v in check_with_iodata(stem + ".fchk", ref).items()})


if __name__ == "__main__":
    main()
