#!/usr/bin/env python3
"""The difference, attachment and detachment densities of a Gaussian TD fchk file, computed
without orbcloud: numpy reads the fchk's records, PySCF builds the molecule from the fchk's own
shells and evaluates the basis functions (`mol.eval_gto`), and numpy diagonalises the
difference density in the Löwdin basis (Head-Gordon et al., J. Phys. Chem. 99, 14261 (1995)).

    python3 scripts/excited_reference.py FILE.fchk > reference.json

Prints JSON: the points (bohr), rho_ground, rho_excited, difference, attachment, detachment at
each, the electrons moved (sum of the positive eigenvalues), the detached electrons, tr(dP S),
and the attachment's and detachment's centroids from PySCF's dipole integrals (`int1e_r`).

Conventions taken from the fchk, not from orbcloud: shell types 0 s, 1 p, -1 sp (s then p with
the `P(S=P)` coefficients), -l pure in Gaussian's order m = 0, +1, -1, +2, -2 (PySCF orders
-l..l), coefficients over normalised primitives with the contraction normalised (as PySCF does
with a basis given this way); density matrices are lower triangles, row by row. Cartesian d and
higher (whose component normalisation differs between the two programs) are refused.

The points: 300 uniform in the atoms' box plus 3 bohr (seed 5), each nucleus, and 20 points
within 0.5 bohr of nuclei.
"""
import json
import sys

import numpy as np
from pyscf import gto


def records(path):
    """Every numeric record of an fchk file, by label: a number or a numpy array."""
    out = {}
    lines = open(path).read().splitlines()
    k = 2
    while k < len(lines):
        line = lines[k]
        k += 1
        if len(line) < 45 or line.startswith(" "):
            continue
        label, kind, rest = line[:43].strip(), line[43], line[44:].split()
        if kind not in "IR":
            continue
        if rest and rest[0] == "N=":
            n = int(rest[1])
            values = []
            while len(values) < n:
                values.extend(lines[k].split())
                k += 1
            cast = int if kind == "I" else float
            out[label] = np.array([cast(v) for v in values])
        elif rest:
            out[label] = int(rest[0]) if kind == "I" else float(rest[0])
    return out


def molecule(r):
    """PySCF's molecule of the fchk's shells, and per PySCF function the fchk's function."""
    z = r["Atomic numbers"].astype(int)
    xyz = r["Current cartesian coordinates"].reshape(-1, 3)
    types = r["Shell types"].astype(int)
    nprim = r["Number of primitives per shell"].astype(int)
    owner = r["Shell to atom map"].astype(int) - 1
    exps, coefs = r["Primitive exponents"], r["Contraction coefficients"]
    sp = r.get("P(S=P) Contraction coefficients")
    if any(t >= 2 for t in types):
        raise NotImplementedError("cartesian d or higher")
    # One "atom" label per centre, so each holds its own basis.
    atoms = [(f"X{i}", xyz[i]) for i in range(len(z))]
    basis = {f"X{i}": [] for i in range(len(z))}
    # The fchk's functions, shell by shell, each as (atom, shell index on the atom, l, m-slot).
    fchk_functions = []
    per_atom_shells = [[] for _ in z]
    p0 = 0
    for t, n, a in zip(types, nprim, owner):
        e, c = exps[p0 : p0 + n], coefs[p0 : p0 + n]
        shells = [(0, c)] if t == 0 else [(0, c), (1, sp[p0 : p0 + n])] if t == -1 else [(abs(t), c)]
        for l, cc in shells:
            basis[f"X{a}"].append([l] + [[float(x), float(y)] for x, y in zip(e, cc)])
            # Which shell of this l on the atom: PySCF sorts an atom's shells by l (stably).
            shell_on_atom = per_atom_shells[a].count(l)
            per_atom_shells[a].append(l)
            if l == 1:
                slots = ["x", "y", "z"]
            elif l == 0:
                slots = [0]
            else:
                # Gaussian's pure order: 0, +1, -1, +2, -2, ...
                slots = [0] + [s * m for m in range(1, l + 1) for s in (1, -1)]
            fchk_functions += [(a, shell_on_atom, l, s) for s in slots]
        p0 += n
    mol = gto.Mole()
    mol.atom = [(f"X{i}", tuple(p)) for i, (_, p) in enumerate(atoms)]
    mol.unit = "Bohr"
    mol.basis = basis
    mol.cart = False
    mol.charge = 0
    mol.spin = None
    # Ghost-like labels carry no nuclear charge; the electron count is irrelevant here.
    mol.nelectron = 0
    mol.build(verbose=0)
    # PySCF's functions, shell by shell as it holds them (an atom's sorted by l), p as x y z,
    # pure m = -l..l.
    pyscf_functions = []
    seen = {}
    for b in range(mol.nbas):
        a, l = mol.bas_atom(b), mol.bas_angular(b)
        rank = seen.get((a, l), 0)
        seen[(a, l)] = rank + 1
        for _ in range(mol.bas_nctr(b)):
            if l == 1:
                slots = ["x", "y", "z"]
            elif l == 0:
                slots = [0]
            else:
                slots = list(range(-l, l + 1))
            pyscf_functions += [(a, rank, l, m) for m in slots]
    where = {f: i for i, f in enumerate(fchk_functions)}
    order = np.array([where[f] for f in pyscf_functions])
    return mol, order


def square(lower, n, order):
    p = np.zeros((n, n))
    p[np.tril_indices(n)] = lower
    p = p + p.T - np.diag(np.diag(p))
    return p[np.ix_(order, order)]


def main():
    r = records(sys.argv[1])
    mol, order = molecule(r)
    n = len(order)
    assert n == r["Number of basis functions"], (n, r["Number of basis functions"])
    label = "Total CI Density" if "Total CI Density" in r else "Total CI Rho(1) Density"
    ground = square(r["Total SCF Density"], n, order)
    excited = square(r[label], n, order)
    delta = excited - ground
    s = mol.intor("int1e_ovlp")
    w, u = np.linalg.eigh(s)
    half = (u * np.sqrt(w)) @ u.T
    inverse_half = (u / np.sqrt(w)) @ u.T
    lam, vec = np.linalg.eigh(half @ delta @ half)
    c = inverse_half @ vec
    attach = (c[:, lam > 0] * lam[lam > 0]) @ c[:, lam > 0].T
    detach = (c[:, lam < 0] * -lam[lam < 0]) @ c[:, lam < 0].T

    xyz = mol.atom_coords()
    rng = np.random.default_rng(5)
    lo, hi = xyz.min(axis=0) - 3.0, xyz.max(axis=0) + 3.0
    near = xyz[rng.integers(0, len(xyz), 20)] + rng.normal(scale=0.25, size=(20, 3))
    points = np.vstack([lo + (hi - lo) * rng.random((300, 3)), xyz, near])
    ao = mol.eval_gto("GTOval_sph", points)

    def rho(p):
        return np.einsum("pi,ij,pj->p", ao, p, ao)

    dipole = mol.intor("int1e_r")

    def centroid(p):
        return (np.einsum("xij,ji->x", dipole, p) / np.trace(p @ s)).tolist()

    json.dump(
        {
            "points": points.tolist(),
            "rho_ground": rho(ground).tolist(),
            "rho_excited": rho(excited).tolist(),
            "difference": rho(delta).tolist(),
            "attachment": rho(attach).tolist(),
            "detachment": rho(detach).tolist(),
            "electrons_moved": float(lam[lam > 0].sum()),
            "electrons_detached": float(-lam[lam < 0].sum()),
            "trace_delta_s": float(np.trace(delta @ s)),
            "attachment_centroid": centroid(attach),
            "detachment_centroid": centroid(detach),
        },
        sys.stdout,
    )


if __name__ == "__main__":
    main()
