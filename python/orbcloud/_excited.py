"""A PySCF TDA, TDHF or TDDFT calculation in orbcloud's terms: imported only by
:func:`orbcloud.from_pyscf`, so PySCF stays optional.

The amplitudes are PySCF's ``td.xy``: per state X (and Y, TDHF/TDDFT) over occupied × virtual
orbitals, normalised as PySCF normalises them (restricted: |X|² − |Y|² = ½, each spin's share
of a spin-adapted excitation; unrestricted: |Xα|² + |Xβ|² − |Yα|² − |Yβ|² = 1). From them:

* the states' main transitions (|amplitude| ≥ 0.1, as PySCF and Gaussian print them);
* natural transition orbitals (Martin, JCP 118, 4775 (2003)): the SVD X/|X| = U Σ Vᵀ, hole k =
  C_occ U_k, particle k = C_vir V_k, weight σ_k², X alone (as PySCF's ``get_nto``) and each
  orbital's sign chosen as ``get_nto`` chooses it (its largest MO coefficient positive);
* the unrelaxed difference density matrix (the one PySCF's TDDFT gradients start from), per
  spin ΔP_σ = C_vir (XᵀX + YᵀY) C_virᵀ − C_occ (XXᵀ + YYᵀ) C_occᵀ, doubled for a restricted
  calculation's two spins: its attachment holds 2(|X|² + |Y|²) electrons (1 for TDA).
"""

from __future__ import annotations

import numpy as np

# Amplitudes below this are left out of a state's listed transitions.
TRANSITION_THRESHOLD = 0.1


def is_td(obj) -> bool:
    """Whether ``obj`` looks like a PySCF TD object (TDA, TDHF, TDDFT, restricted or not)."""
    return hasattr(obj, "xy") and hasattr(obj, "_scf") and hasattr(obj, "e") and hasattr(obj, "nstates")


def _norm2(a: np.ndarray) -> float:
    return float(np.sum(a**2))


class Amplitudes:
    """A TD calculation's states and amplitudes, copied when the document is made (PySCF's
    ``get_nto`` rescales ``td.xy`` in place)."""

    def __init__(self, td):
        if td.xy is None or td.e is None:
            raise ValueError("from_pyscf takes a TD object that has run (td.kernel() or td.run())")
        mf = td._scf
        self.mol = td.mol
        mo_coeff = np.asarray(mf.mo_coeff)
        mo_occ = np.asarray(mf.mo_occ)
        if np.iscomplexobj(mo_coeff):
            raise ValueError("complex orbitals (GHF, complex RHF) are not supported")
        self.restricted = mo_coeff.ndim == 2
        mask = np.asarray(td.get_frozen_mask()) if hasattr(td, "get_frozen_mask") else None
        # Per spin: the occupied and virtual orbitals' coefficients (PySCF's AOs) and their
        # 0-based numbers among all orbitals of that spin.
        self.spaces = []
        for s in range(1 if self.restricted else 2):
            c = mo_coeff if self.restricted else mo_coeff[s]
            occ = mo_occ if self.restricted else mo_occ[s]
            m = np.ones(c.shape[1], dtype=bool) if mask is None else (mask if mask.ndim == 1 else mask[s])
            kept = np.flatnonzero(m)
            o, v = kept[occ[kept] > 0], kept[occ[kept] == 0]
            self.spaces.append((c[:, o].copy(), c[:, v].copy(), o, v))
        self.ground = np.asarray(mf.make_rdm1(), dtype=float)
        if not self.restricted:
            self.ground = self.ground[0] + self.ground[1]
        self.singlet = bool(getattr(td, "singlet", True)) if self.restricted else None
        self.energies = np.asarray(td.e, dtype=float).copy()
        self.e_tot = float(mf.e_tot)
        # Copies of X and Y per state, per spin (Y zero for TDA), rescaled to PySCF's norm.
        self.xy = []
        for x, y in td.xy:
            xs = [np.array(a, dtype=float) for a in self._per_spin(x)]
            ys = [np.array(b, dtype=float) if isinstance(b, np.ndarray) else np.zeros_like(a) for a, b in zip(xs, self._per_spin(y))]
            norm = sum(_norm2(a) for a in xs) - sum(_norm2(b) for b in ys)
            target = 0.5 if self.restricted else 1.0
            scale = np.sqrt(target / norm) if norm > 0 else 1.0
            self.xy.append(([a * scale for a in xs], [b * scale for b in ys]))
        self.tda = all(not np.any(b) for _, ys in self.xy for b in ys)
        kind = "TDA" if self.tda else ("TDDFT" if hasattr(mf, "xc") else "TDHF")
        reference = str(mf.xc).upper() if hasattr(mf, "xc") else "HF"
        self.method = f"{kind} ({reference})"
        try:
            self.strengths = np.asarray(td.oscillator_strength(), dtype=float)
        except Exception:  # an oscillator strength is a courtesy; older PySCF may lack it
            self.strengths = None
        self.symmetries = self._symmetries(td) if self.restricted else [""] * len(self.xy)

    def _symmetries(self, td) -> list[str]:
        """Each state's irreducible representation as PySCF's ``analyze`` names it, where the
        molecule has symmetry on ("" otherwise, and "???" for a state that mixes irreps)."""
        mol = self.mol
        if not getattr(mol, "symmetry", False):
            return [""] * len(self.xy)
        try:  # a courtesy, through PySCF's own (private) helper
            from pyscf import symm
            from pyscf.scf import hf_symm
            from pyscf.tdscf.rhf import _analyze_wfnsym

            c_occ, c_vir, o, v = self.spaces[0]
            orbsym = np.asarray(hf_symm.get_orbsym(mol, np.asarray(td._scf.mo_coeff)))
            x_sym = symm.direct_prod(orbsym[o], orbsym[v], mol.groupname)
            return [str(_analyze_wfnsym(td, x_sym, xs[0])) for xs, _ in self.xy]
        except Exception:
            return [""] * len(self.xy)

    def _per_spin(self, a) -> list:
        """A restricted amplitude as a one-spin list, an unrestricted pair as a list (PySCF's
        TDA gives Y as 0, or (0, 0))."""
        if self.restricted:
            return [a]
        return list(a) if isinstance(a, (tuple, list)) else [a, a]

    def __len__(self) -> int:
        return len(self.xy)

    def _index(self, state: int) -> int:
        if isinstance(state, bool) or not isinstance(state, (int, np.integer)) or not 1 <= state <= len(self):
            raise ValueError(f"state {state!r}: the calculation has states 1 to {len(self)}")
        return int(state) - 1

    def states(self) -> list[tuple]:
        """``_native.Document.with_states``'s states: number, eV, total energy, f, spin,
        symmetry, ⟨S²⟩, transitions."""
        from pyscf.data import nist

        out = []
        for k, (xs, ys) in enumerate(self.xy):
            transitions = []
            for s, (x, y) in enumerate(zip(xs, ys)):
                _, _, o, v = self.spaces[s]
                spin = "" if self.restricted else ("alpha", "beta")[s]
                for amplitudes, back in ((x, False), (y, True)):
                    for i, a in zip(*np.nonzero(np.abs(amplitudes) >= TRANSITION_THRESHOLD)):
                        transitions.append((int(o[i]) + 1, int(v[a]) + 1, float(amplitudes[i, a]), spin, back))
            transitions.sort(key=lambda t: -abs(t[2]))
            spin = ("Singlet" if self.singlet else "Triplet") if self.restricted else ""
            f = None if self.strengths is None else float(self.strengths[k])
            e = float(self.energies[k])
            out.append((k + 1, e * nist.HARTREE2EV, self.e_tot + e, f, spin, self.symmetries[k], None, transitions))
        return out

    def nto(self, state: int):
        """(weights, coefficients, occupations, labels, spins) of state ``state``'s natural
        transition orbitals, pairs interleaved (hole 1, particle 1, hole 2, …), weights
        descending; coefficients over PySCF's AOs (n_ao × n_orbitals, per spin)."""
        xs, _ = self.xy[self._index(state)]
        total = np.sqrt(sum(_norm2(x) for x in xs))
        sets = []
        for s, x in enumerate(xs):
            c_occ, c_vir, _, _ = self.spaces[s]
            u, sigma, vt = np.linalg.svd(x / total, full_matrices=False)
            v = vt.T
            for m in (u, v):  # each orbital's largest MO coefficient positive, as get_nto
                rows = np.argmax(np.abs(m), axis=0)
                m[:, m[rows, np.arange(m.shape[1])] < 0] *= -1
            holes, particles = c_occ @ u, c_vir @ v
            pairs = len(sigma)
            coefficients = np.empty((holes.shape[0], 2 * pairs))
            coefficients[:, 0::2], coefficients[:, 1::2] = holes, particles
            weights = sigma**2
            labels = [f"{kind} {k + 1}" for k in range(pairs) for kind in ("hole", "particle")]
            sets.append((weights, coefficients, np.repeat(weights, 2), labels))
        return sets

    def difference(self, state: int) -> np.ndarray:
        """The unrelaxed difference density matrix ΔP of state ``state`` (both spins, PySCF's AOs)."""
        xs, ys = self.xy[self._index(state)]
        factor = 2.0 if self.restricted else 1.0
        delta = np.zeros_like(self.ground)
        for s, (x, y) in enumerate(zip(xs, ys)):
            c_occ, c_vir, _, _ = self.spaces[s]
            d_vv = x.T @ x + y.T @ y
            d_oo = x @ x.T + y @ y.T
            delta += factor * (c_vir @ d_vv @ c_vir.T - c_occ @ d_oo @ c_occ.T)
        return delta
