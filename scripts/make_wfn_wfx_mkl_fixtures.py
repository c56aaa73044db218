#!/usr/bin/env python3
"""Writes tests/fixtures/wfn_wfx_mkl/: PySCF wavefunctions as AIM .wfn, AIMAll .wfx and ORCA .mkl
files, each in the layout its programs write, beside the same wavefunction as a Molden file
(PySCF's own writer). tests/aim_wavefunctions.rs checks that every file opens with the Molden
file's orbitals, density, energies, occupations and spins.
`--seeds DIR` writes the fuzzing seeds instead: H2 RHF/STO-3G and OH UHF/3-21G in each layout,
occupied orbitals only, under DIR/wfn, DIR/wfx and DIR/mkl (scripts/fuzz.sh calls it).

Systems (symmetry off, so the input coordinates are kept); the basis is cc-pVDZ with, on O, one
f (exponent 1.4) and one g (1.2) function added, so that every file carries s to g:
  h2o_rhf    H2O RHF
  oh_uhf     OH  UHF doublet
  oh_rohf    OH  ROHF doublet

Files per system:
  NAME.molden        pyscf.tools.molden.from_scf (pure d, f, g)
  h2o_rhf.wfn        Gaussian's layout (AIMPAC's fixed columns: `GAUSSIAN  n MOL ORBITALS …`,
                     atoms `(CENTRE n)` … `CHARGE =`, 20I3 assignments, D14.7 exponents, MO lines
                     `MO n MO 0.0 OCC NO = … ORB. ENERGY = …` (F13.7, F12.6), D16.8 coefficients,
                     `END DATA`, the energy line). Gaussian expands each contracted shell, so the
                     primitives shared by cc-pVDZ's general contractions appear more than once;
                     components in Gaussian's cartesian order (d xx yy zz xy xz yz, f as Molden,
                     g reverse alphabetical), every primitive of a component in a row.
  h2o_rhf_pyscf.wfn  PySCF's layout (pyscf.tools.wfn_format: free spacing, `MO  n  OCC NO = …`,
                     %15.8E coefficients, duplicates merged, PySCF's component order).
  oh_uhf.wfn         Gaussian's layout for UHF: the alpha orbitals, then the beta ones numbered on
                     (the format has no spin field; readers infer it).
  oh_rohf.wfn        Gaussian's layout, ROHF: occupied orbitals only (occupations 2 and 1).
  NAME.wfx           AIMAll's tagged layout as Gaussian writes it (one value per line for
                     scalars, 5 per line for arrays, %20.12e), spin types `Alpha and Beta` /
                     `Alpha` (restricted, ROHF) or `Alpha` / `Beta` (UHF); h2o_rhf.wfx carries
                     `<!-- … -->` comments; the ROHF file holds the occupied orbitals only, as
                     Gaussian writes it.
  NAME.mkl           ORCA's orca_2mkl layout: `$MKL`, `$CHAR_MULT`, `$COORD` (Z, x y z in Å),
                     `$CHARGES`, `$BASIS` (`2l+1 L 1.0` shell headers, `$$` between atoms),
                     `$COEFF_ALPHA`/`$COEFF_BETA` in blocks of 5 orbitals (symmetry labels,
                     energies, one row per basis function), `$OCC_ALPHA`/`$OCC_BETA`, with ORCA's
                     conventions: pure functions in the order m = 0, +1, −1, +2, −2, …; contraction
                     coefficients with the primitive normalisation of the s, x, xy, xyz, xxyz
                     component folded in; the m = ±3 and ±4 functions of f and g with opposite sign.

Precision: the .wfn files keep each program's number formats (Gaussian: 8 significant digits,
energies to 1e-6); the .wfx files write 13 significant digits as AIMAll does; the .mkl files keep
ORCA's columns but write 10 decimals instead of ORCA's 7, so that the comparison tests the reader
rather than the rounding.

Every primitive expansion is checked here against PySCF's own orbital values (mol.eval_gto)
before it is written.

Run:   python scripts/make_wfn_wfx_mkl_fixtures.py [--check]
       (PySCF 2.x.) --check also reads every file back with IOData (pip install qc-iodata), an
       independent reader, and prints max |<φ_file|φ_molden> − δ| over the orbitals, computed with
       IOData's own overlap integrals.
"""
import os
import re
import sys

import numpy as np
import pyscf
from pyscf import gto, lib, scf
from pyscf.tools import molden

OUT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "tests", "fixtures", "wfn_wfx_mkl")
MAX_BYTES = 150_000
ANGSTROM = 0.52917721092  # Å per bohr (PySCF's value)

H2O = "O 0.0 0.0 0.1173; H 0.0 0.7572 -0.4692; H 0.0 -0.7572 -0.4692"
OH = "O 0.0 0.0 0.0; H 0.0 0.0 0.9697"


def basis():
    extra = [[3, [1.4, 1.0]], [4, [1.2, 1.0]]]
    return {"O": gto.basis.load("cc-pvdz", "O") + extra, "H": "cc-pvdz"}


# name, geometry (Å), charge, 2S, method
SYSTEMS = [
    ("h2o_rhf", H2O, 0, 0, "RHF"),
    ("oh_uhf", OH, 0, 1, "UHF"),
    ("oh_rohf", OH, 0, 1, "ROHF"),
]


# Fuzzing seeds (`--seeds DIR`): the same layouts for the smallest molecules, since a fuzzer's
# speed falls with its inputs' size (the fixtures above ran at 1 400 executions a second).
SEEDS = [
    ("h2_rhf", "H 0.0 0.0 0.0; H 0.0 0.0 0.74", 0, 0, "RHF", "sto-3g"),
    ("oh_uhf", OH, 0, 1, "UHF", "3-21g"),
]


def run_scf(geometry, charge, spin, method, basis_set=None):
    mol = gto.M(atom=geometry, basis=basis_set or basis(), charge=charge, spin=spin, symmetry=False,
                unit="Angstrom", verbose=0)
    mf = {"RHF": scf.RHF, "UHF": scf.UHF, "ROHF": scf.ROHF}[method](mol)
    mf.conv_tol = 1e-11
    mf.kernel()
    assert mf.converged, method
    return mol, mf


def spin_sets(mf):
    """(spin, energies, coefficients, occupations) per spin; one set for RHF and ROHF."""
    if mf.mo_coeff.ndim == 3:
        return [("Alpha", mf.mo_energy[0], mf.mo_coeff[0], mf.mo_occ[0]),
                ("Beta", mf.mo_energy[1], mf.mo_coeff[1], mf.mo_occ[1])]
    return [("Alpha", mf.mo_energy, mf.mo_coeff, mf.mo_occ)]


# ----------------------------------------------------------------------------------------
# Cartesian orders and AIM primitive types.

def powers(name):
    return (name.count("x"), name.count("y"), name.count("z"))


def pyscf_cart(l):
    return [(a, b, l - a - b) for a in range(l, -1, -1) for b in range(l - a, -1, -1)]


# AIMAll's primitive types (the table IOData and Multiwfn use): 1 s; 2-4 x y z; 5-10 xx yy zz
# xy xz yz; 11-20 xxx yyy zzz xxy xxz yyz xyy xzz yzz xyz; 21-35 xxxx yyyy zzzz xxxy xxxz xyyy
# yyyz xzzz yzzz xxyy xxzz yyzz xxyz xyyz xyzz.
AIM_NAMES = (["", "x", "y", "z", "xx", "yy", "zz", "xy", "xz", "yz",
              "xxx", "yyy", "zzz", "xxy", "xxz", "yyz", "xyy", "xzz", "yzz", "xyz",
              "xxxx", "yyyy", "zzzz", "xxxy", "xxxz", "xyyy", "yyyz", "xzzz", "yzzz",
              "xxyy", "xxzz", "yyzz", "xxyz", "xyyz", "xyzz"])
AIM_TYPE = {powers(n): k + 1 for k, n in enumerate(AIM_NAMES)}


def gaussian_cart(l):
    """Gaussian's cartesian component order (wfn, wfx and fchk)."""
    if l < 2:
        return pyscf_cart(l)
    if l == 2:
        return [powers(n) for n in "xx yy zz xy xz yz".split()]
    if l == 3:
        return [powers(n) for n in "xxx yyy zzz xyy xxy xxz xzz yzz yyz xyz".split()]
    return pyscf_cart(l)[::-1]


# ----------------------------------------------------------------------------------------
# Primitive expansion: orbital coefficients over unnormalised x^a y^b z^c exp(-α r²).

def primitive_blocks(mol, mo_coeff):
    """Per (shell, contraction): atom, l, exponents (np), and coefficients [np, ncart, nmo] over
    unnormalised cartesian primitives in PySCF's cartesian order (as pyscf.tools.wfn_format)."""
    out = []
    p0 = 0
    for ib in range(mol.nbas):
        l = mol.bas_angular(ib)
        es = mol.bas_exp(ib)
        c = mol._libcint_ctr_coeff(ib)  # radial normalisation included
        nprim, nctr = c.shape
        nd = 2 * l + 1
        c2s = gto.cart2sph(l)  # [ncart, 2l+1], angular factors included
        for k in range(nctr):
            sub = mo_coeff[p0 + k * nd:p0 + (k + 1) * nd]  # [2l+1, nmo]
            cart = np.einsum("cy,yi->ci", c2s, sub)  # [ncart, nmo]
            out.append((mol.bas_atom(ib), l, es, c[:, k][:, None, None] * cart[None]))
        p0 += nd * nctr
    assert p0 == mol.nao_nr()
    return out


def check_blocks(mol, mo_coeff, blocks):
    """The expansion reproduces PySCF's orbital values."""
    rng = np.random.default_rng(7)
    pts = rng.normal(scale=1.5, size=(40, 3))
    want = mol.eval_gto("GTOval_sph", pts) @ mo_coeff
    got = np.zeros_like(want)
    xyz = mol.atom_coords(unit="Bohr")
    for atom, l, es, coef in blocks:
        d = pts - xyz[atom]
        r2 = (d * d).sum(1)
        for p, a in enumerate(es):
            g = np.exp(-a * r2)
            for k, (i, j, m) in enumerate(pyscf_cart(l)):
                got += np.outer(g * d[:, 0] ** i * d[:, 1] ** j * d[:, 2] ** m, coef[p, k])
    assert np.abs(got - want).max() < 1e-12, np.abs(got - want).max()


def aim_primitives(mol, mo_coeff, layout):
    """(centres, types, exponents, coefficients [nprim, nmo]) in a writer's primitive order.
    "gaussian": every contraction expanded on its own (duplicates kept), per shell the
    components in Gaussian's order, each with all the shell's primitives in a row. "pyscf":
    duplicates summed (pyscf.tools.wfn_format uncontracts first), PySCF's component order."""
    blocks = primitive_blocks(mol, mo_coeff)
    check_blocks(mol, mo_coeff, blocks)
    centres, types, exps, coefs = [], [], [], []
    if layout == "pyscf":
        merged = {}
        order = []
        for atom, l, es, coef in blocks:
            for p, a in enumerate(es):
                key = (atom, l, float(a))
                if key not in merged:
                    merged[key] = np.zeros_like(coef[p])
                    order.append(key)
                merged[key] += coef[p]
        # Shells of one (atom, l), exponent by exponent, components of each in PySCF's order.
        for key in order:
            atom, l, a = key
            for k, pw in enumerate(pyscf_cart(l)):
                centres.append(atom + 1)
                types.append(AIM_TYPE[pw])
                exps.append(a)
                coefs.append(merged[key][k])
    else:
        for atom, l, es, coef in blocks:
            pyscf_order = pyscf_cart(l)
            for pw in gaussian_cart(l):
                k = pyscf_order.index(pw)
                for p, a in enumerate(es):
                    centres.append(atom + 1)
                    types.append(AIM_TYPE[pw])
                    exps.append(a)
                    coefs.append(coef[p, k])
    return centres, types, exps, np.array(coefs)


# ----------------------------------------------------------------------------------------
# Number formats.

def fortran_e(x, width, digits, letter="D"):
    """Fortran's Ew.d: 0.ddddd followed by the exponent (D or E), right-aligned."""
    if x == 0:
        s = "0." + "0" * digits + letter + "+00"
    else:
        m, e = ("%.*E" % (digits - 1, abs(x))).split("E")
        s = "0." + m.replace(".", "") + letter + "%+03d" % (int(e) + 1)
        s = ("-" if x < 0 else "") + s
    return s.rjust(width)


def rows(values, per_line, fmt):
    return ["".join(fmt(v) for v in values[i:i + per_line]) for i in range(0, len(values), per_line)]


# ----------------------------------------------------------------------------------------
# .wfn


def write_wfn(path, title, mol, mf, layout, occupied_only=False):
    sets = spin_sets(mf)
    nmo_total = []
    # (number, occupation, energy, coefficients over primitives)
    orbitals = []
    prims = None
    n = 0
    for _, energies, coeff, occ in sets:
        keep = np.where(occ > 0)[0] if occupied_only else np.arange(len(occ))
        centres, types, exps, c = aim_primitives(mol, coeff[:, keep], layout)
        prims = (centres, types, exps)
        for j, i in enumerate(keep):
            n += 1
            orbitals.append((n, occ[i], energies[i], c[:, j]))
        nmo_total.append(len(keep))
    centres, types, exps = prims
    lines = []
    if layout == "pyscf":
        lines.append(title)
        lines.append("GAUSSIAN            %3d MOL ORBITALS    %3d PRIMITIVES      %3d NUCLEI"
                     % (len(orbitals), len(exps), mol.natm))
        for ia in range(mol.natm):
            x, y, z = mol.atom_coord(ia)
            lines.append("  %-4s %-4d (CENTRE%3d)  %11.8f %11.8f %11.8f  CHARGE = %.1f"
                         % (mol.atom_pure_symbol(ia), ia + 1, ia + 1, x, y, z, mol.atom_charge(ia)))
        lines += ["CENTRE ASSIGNMENTS  " + r for r in rows(centres, 20, lambda v: "%3d" % v)]
        lines += ["TYPE ASSIGNMENTS    " + r for r in rows(types, 20, lambda v: "%3d" % v)]
        lines += ["EXPONENTS  " + " ".join("%13.7E" % v for v in exps[i:i + 5]) for i in range(0, len(exps), 5)]
        for number, occ, energy, c in orbitals:
            lines.append("MO  %-4d                  OCC NO = %12.8f ORB. ENERGY = %12.8f" % (number, occ, energy))
            lines += [" " + " ".join("%15.8E" % v for v in c[i:i + 5]) for i in range(0, len(c), 5)]
        lines.append("END DATA")
        lines.append("RHF      ENERGY =        0.0000000000   VIRIAL(-V/T)  =   0.00000000")
    else:
        lines.append(" " + title)
        lines.append("GAUSSIAN        %7d MOL ORBITALS%7d PRIMITIVES%9d NUCLEI" % (len(orbitals), len(exps), mol.natm))
        for ia in range(mol.natm):
            x, y, z = mol.atom_coord(ia)
            lines.append("  %-3s%3d    (CENTRE%3d) %12.8f%12.8f%12.8f  CHARGE =%5.1f"
                         % (mol.atom_pure_symbol(ia), ia + 1, ia + 1, x, y, z, mol.atom_charge(ia)))
        lines += ["CENTRE ASSIGNMENTS  " + r for r in rows(centres, 20, lambda v: "%3d" % v)]
        lines += ["TYPE ASSIGNMENTS    " + r for r in rows(types, 20, lambda v: "%3d" % v)]
        lines += ["EXPONENTS " + r for r in rows(exps, 5, lambda v: fortran_e(v, 14, 7))]
        for number, occ, energy, c in orbitals:
            lines.append("MO%5d     MO 0.0        OCC NO =%13.7f  ORB. ENERGY =%12.6f" % (number, occ, energy))
            lines += rows(list(c), 5, lambda v: fortran_e(v, 16, 8))
        lines.append("END DATA")
        lines.append(" THE  HF ENERGY = %19.12f THE VIRIAL(-V/T)=%13.8f" % (mf.e_tot, virial(mol, mf)))
    with open(path, "w") as f:
        f.write("\n".join(lines) + "\n")


def virial(mol, mf):
    dm = mf.make_rdm1()
    if dm.ndim == 3:
        dm = dm[0] + dm[1]
    t = np.einsum("ij,ji", dm, mol.intor("int1e_kin"))
    return -(mf.e_tot - t) / t


# ----------------------------------------------------------------------------------------
# .wfx


def write_wfx(path, title, mol, mf, comments, occupied_only):
    sets = spin_sets(mf)
    restricted = len(sets) == 1
    occs, energies, spins, coefs = [], [], [], []
    prims = None
    for spin, e, coeff, occ in sets:
        keep = np.where(occ > 0)[0] if occupied_only else np.arange(len(occ))
        centres, types, exps, c = aim_primitives(mol, coeff[:, keep], "gaussian")
        prims = (centres, types, exps)
        for j, i in enumerate(keep):
            occs.append(occ[i])
            energies.append(e[i])
            if restricted:
                spins.append("Alpha and Beta" if occ[i] > 1.5 else "Alpha" if occ[i] > 0.5 else "Alpha and Beta")
            else:
                spins.append(spin)
            coefs.append(c[:, j])
    centres, types, exps = prims
    neleca, nelecb = mol.nelec
    e20 = lambda v: " %19.12e" % v
    out = []

    def section(tag, body):
        out.append("<%s>" % tag)
        out.extend(body)
        out.append("</%s>" % tag)

    if comments:
        out.append("<!-- %s: AIMAll's extended wavefunction format -->" % os.path.basename(path))
    section("Title", [" " + title])
    section("Keywords", [" GTO"])
    section("Number of Nuclei", [" %d" % mol.natm])
    section("Number of Occupied Molecular Orbitals", [" %d" % len(occs)])
    section("Number of Perturbations", [" 0"])
    section("Net Charge", [" %d" % mol.charge])
    section("Number of Electrons", [" %d" % mol.nelectron])
    section("Number of Alpha Electrons", [" %d" % neleca])
    section("Number of Beta Electrons", [" %d" % nelecb])
    section("Electronic Spin Multiplicity", [" %d" % (mol.spin + 1)])
    section("Number of Core Electrons", [" 0"])
    if comments:
        out.append("<!-- nuclei: names, atomic numbers, charges,")
        out.append("     coordinates in bohr -->")
    section("Nuclear Names", [" %s%d" % (mol.atom_pure_symbol(i), i + 1) for i in range(mol.natm)])
    section("Atomic Numbers", [" %d" % gto.charge(mol.atom_pure_symbol(i)) for i in range(mol.natm)])
    section("Nuclear Charges", [e20(mol.atom_charge(i)) for i in range(mol.natm)])
    section("Nuclear Cartesian Coordinates", ["".join(e20(v) for v in mol.atom_coord(i)) for i in range(mol.natm)])
    section("Number of Primitives", [" %d" % len(exps)])
    section("Primitive Centers", rows(centres, 5, lambda v: "%20d" % v))
    section("Primitive Types", rows(types, 5, lambda v: "%20d" % v))
    section("Primitive Exponents", rows(exps, 5, e20))
    section("Molecular Orbital Occupation Numbers", [e20(v) for v in occs])
    section("Molecular Orbital Energies", [e20(v) for v in energies])
    section("Molecular Orbital Spin Types", [" " + s for s in spins])
    body = []
    for k, c in enumerate(coefs):
        body += ["<MO Number>", " %d" % (k + 1), "</MO Number>"]
        body += rows(list(c), 5, e20)
    if comments:
        body.insert(0, "<!-- one block per orbital: its number, then its coefficients -->")
    section("Molecular Orbital Primitive Coefficients", body)
    section("Energy = T + Vne + Vee + Vnn", [e20(mf.e_tot)])
    section("Virial Ratio (-V/T)", [e20(virial(mol, mf))])
    with open(path, "w") as f:
        f.write("\n".join(out) + "\n")


# ----------------------------------------------------------------------------------------
# .mkl (ORCA)


def cartesian_norm(alpha, p):
    """Normalisation of x^a y^b z^c exp(-α r²)."""
    def dfact(n):
        return 1.0 if n <= 0 else n * dfact(n - 2)
    l = sum(p)
    pre = (2 * alpha / np.pi) ** 1.5 * (4 * alpha) ** l
    return np.sqrt(pre / np.prod([dfact(2 * k - 1) for k in p]))


# The component whose primitive normalisation ORCA folds into its contraction coefficients.
ORCA_NORM_COMPONENT = {0: (0, 0, 0), 1: (1, 0, 0), 2: (1, 1, 0), 3: (1, 1, 1), 4: (2, 1, 1)}


def write_mkl(path, mol, mf):
    lines = ["$MKL", "#", "# MKL format file in ORCA's orca_2mkl conventions, written from PySCF by",
             "# scripts/make_wfn_wfx_mkl_fixtures.py", "#", "$CHAR_MULT", "  %d %d" % (mol.charge, mol.spin + 1),
             "$END", "", "$COORD"]
    for i in range(mol.natm):
        x, y, z = mol.atom_coord(i) * ANGSTROM
        lines.append("   %d   %12.8f %12.8f %12.8f" % (gto.charge(mol.atom_pure_symbol(i)), x, y, z))
    lines += ["$END", "", "$CHARGES"] + ["   0.000000"] * mol.natm + ["$END", "", "$BASIS"]
    # Shells in PySCF's order per atom (PySCF keeps an atom's shells together).
    last = 0
    sign = []  # per basis function, in Molden order
    aoidx = molden.order_ao_index(mol)
    for ib in range(mol.nbas):
        atom, l = mol.bas_atom(ib), mol.bas_angular(ib)
        assert atom >= last
        if atom != last:
            lines.append("$$")
            last = atom
        es = mol.bas_exp(ib)
        cs = mol.bas_ctr_coeff(ib)
        for k in range(cs.shape[1]):
            lines.append(" %d %s 1.0" % (2 * l + 1, "SPDFGH"[l]))
            for a, c in zip(es, cs[:, k]):
                if c != 0.0:
                    lines.append("%19.9f %21.14f" % (a, c * cartesian_norm(a, ORCA_NORM_COMPONENT[l])))
            flips = [1.0] * (2 * l + 1)
            for m in range(5, min(2 * l + 1, 9)):
                flips[m] = -1.0  # m = ±3 and ±4 after 0, ±1, ±2
            sign += flips
    lines += ["", "$END", ""]
    sign = np.array(sign)
    for spin, energies, coeff, occ in spin_sets(mf):
        c = coeff[aoidx] * sign[:, None]
        lines.append("$COEFF_%s" % spin.upper())
        for i0 in range(0, c.shape[1], 5):
            cols = range(i0, min(i0 + 5, c.shape[1]))
            lines.append(" " + "  ".join(" a1g" for _ in cols))
            lines.append("".join("%18.10f" % energies[i] for i in cols))
            for row in c[:, i0:i0 + 5]:
                lines.append("".join("%16.10f" % v for v in row))
        lines += [" $END", "", "$OCC_%s" % spin.upper()]
        lines += rows(list(occ), 5, lambda v: "%13.7f" % v)
        lines += [" $END", ""]
    with open(path, "w") as f:
        f.write("\n".join(lines) + "\n")


# ----------------------------------------------------------------------------------------
# Independent check with IOData.


def check_with_iodata(path, molden_path):
    import warnings

    from iodata import load_one
    from iodata.overlap import compute_overlap

    text = open(path).read()
    if "<!--" in text:
        # IOData reads no comments: give it the file without them.
        import tempfile
        text = re.sub(r"<!--.*?-->\n", "", text, flags=re.S)
        tmp = tempfile.NamedTemporaryFile("w", suffix=".wfx", delete=False)
        tmp.write(text)
        tmp.close()
        path = tmp.name
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        a = load_one(path)
        b = load_one(molden_path)
    s = compute_overlap(a.obasis, a.atcoords, b.obasis, b.atcoords)
    worst = 0.0
    pairs = [(a.mo.coeffsa, b.mo.coeffsa, a.mo.occsa, b.mo.occsa)]
    if a.mo.kind == "unrestricted" and a.mo.norbb:
        pairs.append((a.mo.coeffsb, b.mo.coeffsb, a.mo.occsb, b.mo.occsb))
    for ca, cb, oa, ob in pairs:
        n = ca.shape[1]
        o = ca.T @ s @ cb[:, :n]
        worst = max(worst, np.abs(o - np.eye(n)).max(), np.abs(oa - ob[:n]).max())
    notes = sorted({str(w.message).split(".")[0] for w in caught if "ORCA" in str(w.message)})
    return worst, notes


def write_seeds(out):
    """Each layout of each seed molecule, occupied orbitals only, into out/{wfn,wfx,mkl}/."""
    for name, geometry, charge, spin, method, basis_set in SEEDS:
        mol, mf = run_scf(geometry, charge, spin, method, basis_set)
        title = "%s %s/%s" % (name, method, basis_set)
        for kind in ("wfn", "wfx", "mkl"):
            os.makedirs(os.path.join(out, kind), exist_ok=True)
        write_wfn(os.path.join(out, "wfn", name + ".wfn"), title, mol, mf, "gaussian", occupied_only=True)
        write_wfx(os.path.join(out, "wfx", name + ".wfx"), title, mol, mf, comments=False, occupied_only=True)
        write_mkl(os.path.join(out, "mkl", name + ".mkl"), mol, mf)


def main():
    if "--seeds" in sys.argv[1:]:
        lib.num_threads(1)
        write_seeds(sys.argv[sys.argv.index("--seeds") + 1])
        return
    check = "--check" in sys.argv[1:]
    os.makedirs(OUT, exist_ok=True)
    lib.num_threads(1)
    for name, geometry, charge, spin, method in SYSTEMS:
        mol, mf = run_scf(geometry, charge, spin, method)
        stem = os.path.join(OUT, name)
        title = "%s %s/cc-pVDZ+fg (PySCF %s)" % (name, method, pyscf.__version__)
        molden.from_scf(mf, stem + ".molden")
        written = [stem + ".molden"]
        if name == "h2o_rhf":
            write_wfn(stem + ".wfn", title, mol, mf, "gaussian")
            write_wfn(stem + "_pyscf.wfn", title, mol, mf, "pyscf")
            written += [stem + ".wfn", stem + "_pyscf.wfn"]
        else:
            write_wfn(stem + ".wfn", title, mol, mf, "gaussian", occupied_only=method == "ROHF")
            written.append(stem + ".wfn")
        write_wfx(stem + ".wfx", title, mol, mf, comments=name == "h2o_rhf", occupied_only=method == "ROHF")
        write_mkl(stem + ".mkl", mol, mf)
        written += [stem + ".wfx", stem + ".mkl"]
        sizes = {os.path.basename(p): os.path.getsize(p) for p in written}
        for p, size in sizes.items():
            assert size < MAX_BYTES, (p, size)
        print("%-8s nao=%3d E=%.10f  %s" % (name, mol.nao_nr(), mf.e_tot, " ".join("%s %d B" % kv for kv in sizes.items())))
        if check:
            for p in written[1:]:
                try:
                    worst, notes = check_with_iodata(p, stem + ".molden")
                except Exception as e:  # IOData refuses restricted open-shell MKL files
                    print("    IOData %-20s refused: %s" % (os.path.basename(p), e))
                    continue
                print("    IOData %-20s max |<file|molden> - I|, occupations: %.1e %s" % (os.path.basename(p), worst, " ".join(notes)))


if __name__ == "__main__":
    main()
