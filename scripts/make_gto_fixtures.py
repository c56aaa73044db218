#!/usr/bin/env python3
"""Writes tests/fixtures/gto/*.json: basis sets, orbitals and reference values from PySCF.

Every number is converted to orbcloud's conventions (see src/model/basis.rs):
- shells: one per contraction column, coefficients for normalised primitives
  (PySCF's `bas_ctr_coeff`), positions in bohr;
- every basis function has unit norm: PySCF's cartesian components are divided by
  sqrt(S_ii) (PySCF normalises only the x^l component);
- pure functions in the order m = 0, +1, -1, +2, -2, ... (PySCF writes m = -l..l);
  p functions stay x, y, z.

Run: python scripts/make_gto_fixtures.py   (PySCF 2.x; output is deterministic)
"""
import json
import os

import numpy as np
from pyscf import gto, scf, dft

OUT = os.path.join(os.path.dirname(__file__), "..", "tests", "fixtures", "gto")


def pure_m(k):
    if k == 0:
        return 0
    return (k + 1) // 2 if k % 2 == 1 else -(k // 2)


def orbcloud_order(mol):
    """PySCF AO index of each orbcloud AO, in orbcloud order."""
    order = []
    off = 0
    for ib in range(mol.nbas):
        l = mol.bas_angular(ib)
        nctr = mol.bas_nctr(ib)
        n = (l + 1) * (l + 2) // 2 if mol.cart else 2 * l + 1
        for c in range(nctr):
            base = off + c * n
            if mol.cart or l <= 1:
                order.extend(base + i for i in range(n))
            else:
                order.extend(base + pure_m(k) + l for k in range(n))
        off += nctr * n
    assert off == mol.nao
    return np.array(order)


def shells(mol):
    out = []
    for ib in range(mol.nbas):
        l = int(mol.bas_angular(ib))
        exps = mol.bas_exp(ib)
        cs = mol.bas_ctr_coeff(ib)
        for c in range(cs.shape[1]):
            out.append({
                "atom": int(mol.bas_atom(ib)),
                "l": l,
                "pure": (not mol.cart) and l >= 2,
                "exponents": [float(e) for e in exps],
                "coefficients": [float(x) for x in cs[:, c]],
            })
    return out


def floats(a):
    return [float(x) for x in np.ravel(a)]


def cart2sph_fixture():
    """orbcloud's cartesian -> pure matrices for l = 0..5 from PySCF's mol.cart2sph_coeff()."""
    basis = {"X": [[l, [1.3, 1.0]] for l in range(6)]}
    mol = gto.M(atom="X 0 0 0", basis=basis, cart=False, spin=None, charge=0, verbose=0)
    mol_c = mol.copy()
    mol_c.cart = True
    mol_c.build()
    c2s = mol.cart2sph_coeff()  # (n_cart, n_sph), PySCF's normalisation and m order
    s_cart = mol_c.intor("int1e_ovlp_cart")
    s_sph = mol.intor("int1e_ovlp_sph")
    assert np.allclose(c2s.T @ s_cart @ c2s, s_sph, atol=1e-12)
    assert np.allclose(np.diag(s_sph), 1.0, atol=1e-12)
    norms = np.sqrt(np.diag(s_cart))
    out = {}
    ic = isp = 0
    for l in range(6):
        nc, ns = (l + 1) * (l + 2) // 2, 2 * l + 1
        block = c2s[ic:ic + nc, isp:isp + ns] * norms[ic:ic + nc, None]
        rows = [block[:, i] for i in range(ns)] if l <= 1 else [block[:, pure_m(k) + l] for k in range(ns)]
        out[str(l)] = [floats(r) for r in rows]
        ic += nc
        isp += ns
    return out


def make(name, atom, basis, cart=False, charge=0, spin=0, method="rhf", n_ao_points=50,
         all_orbitals=True, unit="Angstrom"):
    mol = gto.M(atom=atom, basis=basis, cart=cart, charge=charge, spin=spin, unit=unit,
                symmetry=False, verbose=0)
    if method == "rhf":
        mf = scf.RHF(mol)
    elif method == "uhf":
        mf = scf.UHF(mol)
    else:
        mf = dft.RKS(mol)
        mf.xc = method
    mf.conv_tol = 1e-11
    mf.kernel()
    assert mf.converged, name
    order = orbcloud_order(mol)
    s_py = mol.intor("int1e_ovlp")
    scale = np.sqrt(np.diag(s_py))  # PySCF AO = orbcloud AO * scale
    s = (s_py / np.outer(scale, scale))[np.ix_(order, order)]

    restricted = method != "uhf"
    mo_sets = [(mf.mo_coeff, mf.mo_energy, mf.mo_occ, "alpha")] if restricted else [
        (mf.mo_coeff[0], mf.mo_energy[0], mf.mo_occ[0], "alpha"),
        (mf.mo_coeff[1], mf.mo_energy[1], mf.mo_occ[1], "beta")]
    orbitals = []
    for c, e, occ, spin_name in mo_sets:
        n_occ = int(np.count_nonzero(occ > 0))
        keep = range(c.shape[1]) if all_orbitals else range(min(n_occ + 1, c.shape[1]))
        for i in keep:
            orbitals.append({
                "index": i, "spin": spin_name, "energy": float(e[i]), "occupation": float(occ[i]),
                "coefficients": floats((c[:, i] * scale)[order]),
            })
    c_a, occ_a = mo_sets[0][0], mo_sets[0][2]
    homo = int(np.max(np.nonzero(occ_a > 0)))
    lumo = homo + 1

    rng = np.random.default_rng(20240611)
    coords = mol.atom_coords()
    lo, hi = coords.min(axis=0) - 3.0, coords.max(axis=0) + 3.0
    pts = rng.uniform(lo, hi, size=(40, 3))
    near = coords[rng.integers(0, len(coords), 10)] + rng.normal(scale=0.3, size=(10, 3))
    pts = np.vstack([near, pts])

    ao = mol.eval_gto("GTOval_cart" if cart else "GTOval_sph", pts)
    ao_orb = (ao / scale)[:, order]
    # The same values from the converted data, as a check of the conversion itself.
    c_orb = (c_a * scale[:, None])[order]
    assert np.allclose(ao_orb @ c_orb, ao @ c_a, atol=1e-12)
    assert np.allclose(c_orb.T @ s @ c_orb, np.eye(c_orb.shape[1]), atol=1e-8)
    dm = mf.make_rdm1()
    if restricted:
        rho = np.einsum("pi,ij,pj->p", ao, dm, ao)
        spin_rho = np.zeros_like(rho)
    else:
        ra = np.einsum("pi,ij,pj->p", ao, dm[0], ao)
        rb = np.einsum("pi,ij,pj->p", ao, dm[1], ao)
        rho, spin_rho = ra + rb, ra - rb

    n = mol.nao
    pairs = rng.integers(0, n, size=(40, 2))
    data = {
        "name": name,
        "basis_name": basis if isinstance(basis, str) else "custom",
        "method": method,
        "cart": bool(cart),
        "charge": charge,
        "spin": spin,
        "atoms": [{"z": int(mol.atom_charge(i)), "xyz": floats(coords[i])} for i in range(mol.natm)],
        "shells": shells(mol),
        "n_ao": int(n),
        "restricted": restricted,
        "orbitals": orbitals,
        "homo": homo,
        "lumo": lumo,
        "points": [floats(p) for p in pts],
        "ao_values": [floats(row) for row in ao_orb[:n_ao_points]],
        "homo_values": floats(ao @ c_a[:, homo]),
        "lumo_values": floats(ao @ c_a[:, lumo]),
        "density": floats(rho),
        "spin_density": floats(spin_rho),
        "overlap_diagonal": floats(np.diag(s)),
        "overlap_elements": [[int(i), int(j), float(s[i, j])] for i, j in pairs],
    }
    path = os.path.join(OUT, name + ".json")
    with open(path, "w") as f:
        json.dump(data, f, separators=(",", ":"))
    print(f"{path}: {os.path.getsize(path)} bytes, {n} AOs, {len(orbitals)} orbitals")


WATER = "O 0 0 0.1173; H 0 0.7572 -0.4692; H 0 -0.7572 -0.4692"
BENZENE = """C 0.0000 1.3970 0.0000; C 1.2098 0.6985 0.0000; C 1.2098 -0.6985 0.0000;
C 0.0000 -1.3970 0.0000; C -1.2098 -0.6985 0.0000; C -1.2098 0.6985 0.0000;
H 0.0000 2.4810 0.0000; H 2.1486 1.2405 0.0000; H 2.1486 -1.2405 0.0000;
H 0.0000 -2.4810 0.0000; H -2.1486 -1.2405 0.0000; H -2.1486 1.2405 0.0000"""

if __name__ == "__main__":
    os.makedirs(OUT, exist_ok=True)
    c2s = cart2sph_fixture()
    with open(os.path.join(OUT, "cart2sph.json"), "w") as f:
        json.dump(c2s, f, separators=(",", ":"))
    make("h2o_cart_631gs", WATER, "6-31g*", cart=True)
    make("h2o_pure_ccpvtz", WATER, "cc-pvtz", n_ao_points=25, all_orbitals=False)
    make("n2_ccpvqz", "N 0 0 0; N 0 0 1.0977", "cc-pvqz", n_ao_points=12, all_orbitals=False)
    make("ne_ccpv5z", "Ne 0.1 -0.2 0.3", "cc-pv5z", n_ao_points=15, all_orbitals=False)
    make("benzene_631gs", BENZENE, "6-31g*", method="b3lyp", n_ao_points=20, all_orbitals=False)
    make("h2o_cation_uhf", WATER, "6-31g**", charge=1, spin=1, method="uhf")
