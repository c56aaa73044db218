#!/usr/bin/env python3
"""Compare two NCIPLOT-style cube pairs (PREFIX-dens.cube, PREFIX-grad.cube): the grids must
agree to the digits the headers print; the values are compared at the points neither pair cut
(-grad below 100), in units of the last digit the reference (the first pair, e.g. NCIPLOT's)
prints; the points one pair kept and the other cut are counted. numpy only.

usage: nci_compare.py REF_PREFIX OTHER_PREFIX
"""
import sys

import numpy as np


def read_cube(path):
    with open(path) as f:
        lines = f.readlines()
    first = lines[2].split()
    natoms = abs(int(first[0]))
    origin = np.array([float(v) for v in first[1:4]])
    dims, axes = [], []
    for line in lines[3:6]:
        w = line.split()
        dims.append(int(w[0]))
        axes.append([float(v) for v in w[1:4]])
    values = np.array(" ".join(lines[6 + natoms:]).split(), dtype=float)
    if values.size != np.prod(dims):
        sys.exit(f"{path}: {values.size} values for a {dims} grid")
    return origin, np.array(dims), np.array(axes), values


def main():
    if len(sys.argv) != 3:
        sys.exit(__doc__)
    ref, other = sys.argv[1], sys.argv[2]
    o1, n1, a1, d1 = read_cube(ref + "-dens.cube")
    _, _, _, g1 = read_cube(ref + "-grad.cube")
    o2, n2, a2, d2 = read_cube(other + "-dens.cube")
    _, _, _, g2 = read_cube(other + "-grad.cube")
    if not (np.array_equal(n1, n2) and np.allclose(o1, o2, atol=2e-6) and np.allclose(a1, a2, atol=2e-6)):
        sys.exit(f"grids differ: {n1} {o1} {a1.diagonal()} against {n2} {o2} {a2.diagonal()}")
    kept = g1 < 100.0
    both = kept & (g2 < 100.0)
    # NCIPLOT writes e12.5 (0.12345E+01): the last digit it prints is 10^(e-5), e the
    # exponent; differences are reported in units of that digit at each point.
    def last_digit(v):
        e = np.floor(np.log10(np.maximum(np.abs(v), 1e-300))) + 1
        return 10.0 ** (e - 5)

    dd = np.abs(d1[both] - d2[both])
    dg = np.abs(g1[both] - g2[both])
    ud = dd / last_digit(d1[both])
    ug = dg / last_digit(g1[both])
    print(f"grid {n1[0]}x{n1[1]}x{n1[2]} = {n1.prod()} points, origin {o1} bohr, step {a1[0, 0]} bohr")
    print(f"points the reference kept (grad < 100): {kept.sum()}; also kept by the other: {both.sum()}")
    print(f"points the other kept that the reference cut: {((g2 < 100) & ~kept).sum()}")
    print(f"dens (100 sign(l2) rho): max abs diff {dd.max():.3e}, max {ud.max():.2f} units of the "
          f"reference's last printed digit, sign disagreements {(np.sign(d1[both]) != np.sign(d2[both])).sum()}")
    print(f"grad (s):                max abs diff {dg.max():.3e}, max {ug.max():.2f} units of the "
          f"reference's last printed digit")
    print(f"points differing by more than one unit of the last digit: dens {(ud > 1.0001).sum()}, "
          f"grad {(ug > 1.0001).sum()}")

if __name__ == "__main__":
    main()
