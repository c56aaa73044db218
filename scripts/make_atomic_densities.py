#!/usr/bin/env python3
"""Spherical atomic densities for promolecular NCI, written to assets/atomic_densities.txt.

Hydrogen's density is the exact e^{−2r}/π. Every other neutral atom He–Cm (Z = 2–96) is
computed all-electron by PySCF's spherically averaged Hartree–Fock
(`scf.atom_hf.AtomSphAverageRHF`: the electrons of open shells spread evenly over their m
components, so the density is spherical), in def2-QZVPP for He–Kr and ANO-RCC (PySCF's "ano",
all-electron, the largest range of elements PySCF has without pseudopotentials) for Rb–Cm.
Non-relativistic throughout: ANO-RCC is contracted for a scalar-relativistic Hamiltonian, so
from Rb on the energies lie well above the non-relativistic Hartree–Fock limit (Xe by about
260 hartree) and the cores are only roughly right; the valence tails, where NCI regions lie,
feel it much less. An energy above the previous element's is reported as a warning (the SCF
ended in a wrong configuration).

The density is tabulated as ln ρ at radii spaced evenly in ln r (what the model interpolates
with a natural cubic spline in ln r, so ρ, ρ′ and ρ″ are smooth), then shifted so that the
spline's ∫4πr²ρ dr is Z. Beyond the last radius the model continues ln ρ linearly in r, with
the last interval's slope, at least 1 per bohr.

Run with the Python that has PySCF:
    python scripts/make_atomic_densities.py [assets/atomic_densities.txt] [cache-dir]
A cache folder keeps each atom's tabulated density, so a rerun only redoes what is missing.
"""

import os
import sys
import time

import numpy as np
from pyscf import gto
from pyscf.scf import atom_hf
from scipy.interpolate import CubicSpline
from scipy.integrate import quad

MAX_Z = 96
R_MIN, R_MAX, N_RADII = 1e-4, 16.0, 96
RADII = np.geomspace(R_MIN, R_MAX, N_RADII)
MIN_TAIL_DECAY = 1.0


def directions():
    """Axes, face diagonals and cube diagonals: where ρ is averaged (it is spherical already;
    the average only guards against a solver leaving a shell's m components uneven)."""
    d = [(1, 0, 0), (0, 1, 0), (0, 0, 1)]
    d += [(1, 1, 0), (1, 0, 1), (0, 1, 1), (1, -1, 0), (1, 0, -1), (0, 1, -1)]
    d += [(1, 1, 1), (1, 1, -1), (1, -1, 1), (-1, 1, 1)]
    d = np.array(d, dtype=float)
    return d / np.linalg.norm(d, axis=1)[:, None]


def atomic_density(z):
    if z == 1:
        return np.exp(-2.0 * RADII) / np.pi, -0.5, "exact"
    basis = "def2-qzvpp" if z <= 36 else "ano"
    mol = gto.M(atom=[[z, (0.0, 0.0, 0.0)]], basis=basis, spin=z % 2, verbose=0, cart=False)
    mf = atom_hf.AtomSphAverageRHF(mol)
    mf.verbose = 0
    mf.run()
    dm = mf.make_rdm1()
    if dm.ndim == 3:
        dm = dm[0] + dm[1]
    dirs = directions()
    rho = np.zeros_like(RADII)
    for d in dirs:
        ao = mol.eval_gto("GTOval_sph", RADII[:, None] * d[None, :])
        rho += np.einsum("pi,ij,pj->p", ao, dm, ao)
    return rho / len(dirs), mf.e_tot, basis


def tail_decay(log_rho):
    """How fast ln ρ falls (per bohr) beyond R_MAX: the last interval's slope, at least
    MIN_TAIL_DECAY (a basis' diffuse functions can leave the last points flat)."""
    return max((log_rho[-2] - log_rho[-1]) / (RADII[-1] - RADII[-2]), MIN_TAIL_DECAY)


def spline_integral(log_rho):
    """∫4πr²ρ dr of the natural cubic spline of ln ρ in ln r, with the model's tails: ρ
    constant inside R_MIN, ln ρ linear in r beyond R_MAX."""
    u = np.log(RADII)
    s = CubicSpline(u, log_rho, bc_type="natural")
    inner = 4.0 / 3.0 * np.pi * R_MIN**3 * np.exp(log_rho[0])
    body = quad(lambda t: 4.0 * np.pi * np.exp(3.0 * t + s(t)), u[0], u[-1], limit=400, epsabs=1e-12, epsrel=1e-10)[0]
    kappa = tail_decay(log_rho)
    tail = quad(
        lambda r: 4.0 * np.pi * r * r * np.exp(log_rho[-1] - kappa * (r - R_MAX)), R_MAX, np.inf, epsabs=1e-14
    )[0]
    return inner + body + tail


def main():
    out = sys.argv[1] if len(sys.argv) > 1 else "assets/atomic_densities.txt"
    cache = sys.argv[2] if len(sys.argv) > 2 else None
    if cache:
        os.makedirs(cache, exist_ok=True)
    lines = [
        "# orbcloud spherical atomic densities, made by scripts/make_atomic_densities.py:",
        "# H exact; PySCF spherically averaged all-electron HF (def2-QZVPP He-Kr, ANO-RCC Rb-Cm), non-relativistic.",
        f"# radii: {N_RADII} points from {R_MIN} to {R_MAX} bohr, evenly spaced in ln r",
        "# per element a line `Z energy_hartree basis`, then ln(rho / (e/bohr^3)) at each radius",
        f"radii {R_MIN} {R_MAX} {N_RADII}",
    ]
    previous = 0.0
    for z in range(1, MAX_Z + 1):
        t = time.time()
        path = cache and os.path.join(cache, f"{z}.npz")
        if path and os.path.exists(path):
            saved = np.load(path)
            rho, e, basis = saved["rho"], float(saved["e"]), str(saved["basis"])
        else:
            rho, e, basis = atomic_density(z)
            if path:
                np.savez(path, rho=rho, e=e, basis=basis)
        log_rho = np.log(np.maximum(rho, 1e-300))
        log_rho += np.log(z / spline_integral(log_rho))
        assert abs(spline_integral(log_rho) - z) < 1e-6 * z
        if z > 1 and e > previous:
            print(f"warning: Z={z} E={e:.6f} lies above Z={z - 1}'s {previous:.6f}", flush=True)
        previous = e
        lines.append(f"{z} {e:.8f} {basis}")
        values = [f"{v:.6f}" for v in log_rho]
        lines += [" ".join(values[i : i + 12]) for i in range(0, len(values), 12)]
        print(f"Z={z:3d} E={e:.6f} {basis} ({time.time() - t:.1f} s)", flush=True)
    with open(out, "w") as f:
        f.write("\n".join(lines) + "\n")


if __name__ == "__main__":
    main()
