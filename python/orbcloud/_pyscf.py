"""PySCF objects in orbcloud's conventions (``model::basis``): imported only by
:func:`orbcloud.from_pyscf`, so PySCF stays optional.

PySCF orders a shell's functions contraction by contraction, pure ones m = −l…l (p as x, y, z),
cartesian ones alphabetically as orbcloud does; its cartesian functions of l ≥ 2 share one
radial normalisation, so components differ in norm. orbcloud's functions are unit-normalised,
pure ones ordered m = 0, +1, −1, …: each PySCF function is √S_kk times orbcloud's, which folds
into the coefficients."""

from __future__ import annotations

import numpy as np


def _pure_order(l: int) -> list[int]:
    """Offsets into PySCF's m = −l…l of orbcloud's m = 0, +1, −1, +2, −2, …"""
    order = [l]
    for m in range(1, l + 1):
        order += [l + m, l - m]
    return order


def _spin_sets(mo_coeff, mo_occ, mo_energy):
    """[(coefficients, occupations, energies, spin)]; unrestricted when two sets are given (of
    equal or, as a tuple, unequal numbers of orbitals)."""
    pair = isinstance(mo_coeff, (tuple, list)) and len(mo_coeff) == 2
    if any(np.iscomplexobj(c) for c in (mo_coeff if pair else [mo_coeff])):
        raise ValueError("complex orbitals (GHF, complex RHF) are not supported")
    if pair or np.asarray(mo_coeff).ndim == 3:
        occ = mo_occ if mo_occ is not None else [None, None]
        ene = mo_energy if mo_energy is not None else [None, None]
        return [(np.asarray(mo_coeff[s]), occ[s], ene[s], spin) for s, spin in enumerate(("alpha", "beta"))], False
    return [(np.asarray(mo_coeff), mo_occ, mo_energy, "alpha")], True


def basis_map(mol):
    """orbcloud's shells of ``mol``, for each of orbcloud's functions the PySCF function it is
    (``ao_of``), and the norms √S_kk of PySCF's functions."""
    # Shells, and for each of orbcloud's functions the PySCF function it is.
    shells, ao_of = [], []
    offset = 0
    for ib in range(mol.nbas):
        l = mol.bas_angular(ib)
        atom = mol.bas_atom(ib)
        exponents = np.asarray(mol.bas_exp(ib), dtype=float)
        contractions = np.asarray(mol.bas_ctr_coeff(ib), dtype=float)
        pure = not mol.cart and l >= 2
        count = 2 * l + 1 if pure else (l + 1) * (l + 2) // 2
        for ic in range(mol.bas_nctr(ib)):
            shells.append((int(atom), int(l), bool(pure), exponents.tolist(), contractions[:, ic].tolist()))
            ao_of += [offset + k for k in (_pure_order(l) if pure else range(count))]
            offset += count
    if offset != mol.nao_nr():
        raise ValueError(f"counted {offset} basis functions, PySCF has {mol.nao_nr()}")
    ao_of = np.asarray(ao_of)
    norms = np.sqrt(mol.intor_symmetric("int1e_ovlp").diagonal())
    return shells, ao_of, norms


def to_orbcloud_matrix(mol, matrix, basis=None) -> np.ndarray:
    """A matrix over PySCF's basis functions (a density matrix, n_ao × n_ao) over orbcloud's:
    its rows and columns reordered and scaled as the orbitals' coefficients are."""
    _, ao_of, norms = basis if basis is not None else basis_map(mol)
    m = np.asarray(matrix, dtype=float)
    scale = norms[ao_of]
    return np.ascontiguousarray(m[np.ix_(ao_of, ao_of)] * scale[:, None] * scale[None, :])


def document_parts(mf_or_mol, mo_coeff=None, mo_occ=None, mo_energy=None, labels=None):
    """The arguments of ``_native.from_parts``, and what :func:`write_molden` needs later;
    ``labels`` names the orbitals (by default their symmetry labels, if any)."""
    if mo_coeff is None:
        mf = mf_or_mol
        mol = getattr(mf, "mol", None)
        if mol is None or getattr(mf, "mo_coeff", None) is None:
            raise ValueError("from_pyscf takes a mean-field object that has run, or (mol, mo_coeff, mo_occ, mo_energy)")
        mo_coeff, mo_occ, mo_energy = mf.mo_coeff, mf.mo_occ, mf.mo_energy
    else:
        mol = mf_or_mol
    from pyscf.data.elements import charge as atomic_number

    shells, ao_of, norms = basis_map(mol)
    offset = len(ao_of)

    sets, restricted = _spin_sets(mo_coeff, mo_occ, mo_energy)
    coefficients, energies, occupations, spins = [], [], [], []
    for c, occ, ene, spin in sets:
        c = np.asarray(c, dtype=float)
        if c.ndim != 2 or c.shape[0] != offset:
            raise ValueError(f"mo_coeff has shape {c.shape}; expected ({offset}, n_orbitals)")
        n = c.shape[1]
        coefficients.append((c[ao_of, :] * norms[ao_of, None]).T)
        energies.append(np.full(n, np.nan) if ene is None else np.asarray(ene, dtype=float))
        occupations.append(np.zeros(n) if occ is None else np.asarray(occ, dtype=float))
        spins += [spin] * n
    labels = _labels(mol, sets) if labels is None else [str(n) for n in labels]
    z = [int(atomic_number(mol.atom_pure_symbol(i))) if not _ghost(mol, i) else 0 for i in range(mol.natm)]
    parts = dict(
        source=f"PySCF ({mol.natm} atoms, {offset} basis functions)",
        program="PySCF",
        z=z,
        charges=[float(q) for q in mol.atom_charges()],
        positions=np.ascontiguousarray(mol.atom_coords(unit="Bohr"), dtype=float),
        shells=shells,
        coefficients=np.ascontiguousarray(np.vstack(coefficients)),
        energies=np.concatenate(energies),
        occupations=np.concatenate(occupations),
        spins=spins,
        labels=labels,
        restricted=restricted,
    )
    return parts, (mol, mo_coeff, mo_occ, mo_energy)


def _ghost(mol, i: int) -> bool:
    return mol.atom_charge(i) == 0


def _labels(mol, sets) -> list[str]:
    """Symmetry labels when the molecule has symmetry on, else empty strings."""
    labels: list[str] = []
    for c, _, _, _ in sets:
        names = [""] * np.asarray(c).shape[1]
        if getattr(mol, "symmetry", False) and getattr(mol, "symm_orb", None):
            try:
                from pyscf import symm

                names = list(symm.label_orb_symm(mol, mol.irrep_name, mol.symm_orb, c, check=False))
            except Exception:  # labels are a courtesy; orbitals that mix irreps have none
                pass
        labels += [str(n) for n in names]
    return labels


def write_molden(keep, path: str) -> None:
    """Writes PySCF's orbitals kept by :func:`document_parts` as a Molden file (PySCF's writer)."""
    from pyscf.tools import molden

    mol, mo_coeff, mo_occ, mo_energy = keep
    sets, _ = _spin_sets(mo_coeff, mo_occ, mo_energy)
    with open(path, "w") as f:
        molden.header(mol, f)
        for c, occ, ene, spin in sets:
            molden.orbital_coeff(mol, f, np.asarray(c), ene=ene, occ=occ, spin="Alpha" if spin == "alpha" else "Beta")
